"""The online commands (docs/user-guide.md, "Online commands") against a real
`syncplc run` through its HTTP API: status, read, write, force, unforce,
watch, load (--check), rollback, events --url, reload --url; refusals in
words with their exit statuses; a write read back with pymodbus.

    /usr/bin/python3 tests/peers/test_online_commands.py build/syncplc
"""

import os
import re
import subprocess

import peerlib

BINARY = peerlib.syncplc_binary()
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
PASSWORDS = {"olga": "olga-secret-2", "erik": "erik-secret-3"}


def cli(*args, user=None, stdin=None, expect=0):
    env = dict(os.environ)
    if user:
        env["SYNCPLC_PASSWORD"] = PASSWORDS[user]
        args = args + ("--user", user)
    p = subprocess.run([BINARY, *args], env=env, input=stdin, capture_output=True, text=True, timeout=120)
    if p.returncode != expect:
        raise AssertionError("syncplc %s: exit %d, expected %d\nstdout:\n%s\nstderr:\n%s"
                             % (" ".join(args), p.returncode, expect, p.stdout, p.stderr))
    return p.stdout + p.stderr


def main():
    for name, role in (("olga", "operator"), ("erik", "engineer")):
        cli("user", "add", name, "--role", role, "--password-stdin", "--db", DB, stdin=PASSWORDS[name] + "\n")
    srv = peerlib.Server(BINARY, peerlib.project("http_api.yaml"), extra=["--http", "127.0.0.1:0", "--db", DB])
    port = srv.http_port()
    os.environ["SYNCPLC_URL"] = "http://127.0.0.1:%d" % port

    out = cli("status")
    assert "http_api 1.0.0" in out and re.search(r"^main\s+2ms\s+running", out, re.M), out
    out = cli("read", "speed", "pos[2]", "k_iw.OUT")
    assert "speed = 1.5 m/s" in out and "pos[2] = 0.2 m" in out and "k_iw.OUT = -1234" in out, out
    assert "not logged in" in cli("write", "qw_int", "5", expect=2)
    out = cli("write", "qw_int", "321", user="olga")
    mb = peerlib.pymodbus_client(srv.port)
    peerlib.wait_until(lambda: (lambda r: (not r.isError() and r.registers == [321], r))(mb.read_holding_registers(10, 1, slave=1)),
                       "qw_int_r over Modbus after syncplc write")
    cli("write", "speed", "2500 mm/s", user="olga")
    peerlib.wait_until(lambda: ("speed = 2.5 m/s" in cli("read", "speed"), None), "speed in m/s")
    assert "engineer" in cli("force", "iw_const", "9", user="olga", expect=2)
    cli("force", "iw_const", "9", user="erik")
    peerlib.wait_until(lambda: ("iw_const = 9 (forced)" in cli("read", "iw_const"), None), "the force")
    r = mb.read_input_registers(4, 1, slave=1)
    assert not r.isError() and r.registers == [9], r
    out = cli("watch", "iw_const", "qw_int_r", "--count", "3", "--rate", "20")
    lines = [l for l in out.splitlines() if "iw_const = 9 (forced)" in l and "qw_int_r = 321" in l]
    assert len(lines) == 3, out
    assert "released" in cli("unforce", "--all", user="erik")
    peerlib.wait_until(lambda: ("iw_const = -1234" in cli("read", "iw_const"), None), "unforced")
    mb.close()

    here = os.path.dirname(os.path.abspath(__file__))
    d = os.path.join(peerlib.STATE_DIR, "proj")
    os.makedirs(d)
    text = open(os.path.join(here, "http_api.yaml")).read()
    open(os.path.join(d, "main.yaml"), "w").write(text.replace("period: 2ms", "period: 2xs"))
    out = cli("load", os.path.join(d, "main.yaml"), "--check", user="erik", expect=2)
    line = text[:text.index("period: 2ms")].count("\n") + 1
    assert re.search(r"main\.yaml:%d:\d+: .*2xs" % line, out), out
    open(os.path.join(d, "main.yaml"), "w").write(text.replace("version: 1.0.0", "version: 1.1.0"))
    out = cli("load", os.path.join(d, "main.yaml"), user="erik")
    m = re.search(r"version (\d+)", out)
    assert m and "6 kept" in out, out
    assert "http_api 1.1.0" in cli("status")
    out = cli("rollback", "1", user="erik")
    assert "http_api 1.0.0" in cli("status"), out
    cli("reload", "--url", os.environ["SYNCPLC_URL"], user="erik")
    out = cli("events", "--url", os.environ["SYNCPLC_URL"], "--kind", "force")
    assert "forced iw_const to 9 (by erik)" in out, out

    os.environ["SYNCPLC_URL"] = "http://127.0.0.1:9"  # nothing listens on the discard port here
    assert "no syncplc run answers" in cli("status", expect=6)
    srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
