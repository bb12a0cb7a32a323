"""Variables of an ST program (not tags) shown to clients nobody here wrote,
through tags connected from them (docs/st.md): Debian's python3-pymodbus
reads them from the Modbus map and writes the tag the program reads; the
HTTP API (Python's http.client) reads them by instance.path and by tag, and
an engineer writes one (an operator may not); the historian's points of
one are read back with the `sqlite3` shell.

    /usr/bin/python3 tests/peers/test_st_vars.py build/syncplc
"""
import os
import subprocess

import peerlib

BINARY = peerlib.syncplc_binary()
DB = os.path.join(peerlib.STATE_DIR, "st_vars.db")


USERS = {"olga": ("operator", "olga-secret-2"), "erik": ("engineer", "erik-secret-3")}


def login(api, user):
    api.token = None
    api.token = api.expect(200, "POST", "/login", {"user": user, "password": USERS[user][1]}, what="login " + user)["token"]


def main():
    for name, (role, password) in USERS.items():
        peerlib.add_user(BINARY, DB, name, role, password)
    srv = peerlib.Server(BINARY, peerlib.project("st_vars.yaml"), extra=["--http", "127.0.0.1:0", "--db", DB])
    api = peerlib.HttpApi(srv.http_port())
    tally = peerlib.Tally()
    mb = peerlib.Peer(srv.port, tally, unit=srv.unit)

    # The program counts its scans in a variable; the tag follows it scan by scan.
    first = mb.read_values(100, ["DINT"], table="input")[0]
    peerlib.wait_until(lambda: (lambda v: (v >= first + 20, v))(mb.read_values(100, ["DINT"], table="input")[0]),
                       "cell.scans counting on input registers 100..101")
    level = mb.read_values(110, ["LREAL"], table="input")[0]
    assert 0.0 <= level <= 49.5 and level * 2 == int(level * 2), level

    # The HTTP API names the variable itself and the tag.
    def both():
        v = api.expect(200, "GET", "/values?refs=cell.scans,scans_shown,cell.t.Q")
        return v["values"]["cell.scans"] >= v["values"]["scans_shown"] > first, v
    peerlib.wait_until(both, "cell.scans and scans_shown over HTTP")

    # A Modbus client writes the tag the program reads (VAR_EXTERNAL run); the
    # TON inside the program runs, and its Q comes back on a discrete input.
    assert mb.read("discrete", 5, 1) == [False]
    mb.write_coil(0, True)
    peerlib.wait_until(lambda: (mb.read("discrete", 5, 1) == [True], None), "cell.t.Q on discrete input 5")
    assert api.expect(200, "GET", "/values?refs=cell.t.Q")["values"]["cell.t.Q"] is True

    # An engineer writes a variable of the program once (at the start of its
    # task's next scan): the program goes on from it. An operator may not,
    # and a name the program does not have is refused with a suggestion.
    login(api, "olga")
    api.expect(403, "PUT", "/tags/cell.scale", {"value": 2.0}, what="an operator writes an ST variable")
    login(api, "erik")
    j = api.expect(404, "PUT", "/tags/cell.scal", {"value": 2.0}, what="a misspelt variable")
    assert "did you mean scale?" in j["error"], j
    # What a write could not change: a constant the code has compiled in; a
    # subrange's bounds hold as an assignment in ST keeps them.
    j = api.expect(409, "PUT", "/tags/cell.limit", {"value": 1.0}, what="a VAR CONSTANT")
    assert "VAR CONSTANT" in j["error"], j
    j = api.expect(400, "PUT", "/tags/cell.pct", {"value": 150}, what="outside the subrange")
    assert "outside its subrange 0..100" in j["error"], j
    api.expect(200, "PUT", "/tags/cell.pct", {"value": 60}, what="inside the subrange")
    api.expect(400, "PUT", "/tags/cell.scale", {"value": "fast"}, what="not a number")
    j = api.expect(200, "PUT", "/tags/cell.scale", {"value": 2.0}, what="an engineer writes an ST variable")
    assert j["tag"] == "cell.scale" and j["task"] == "main", j
    peerlib.wait_until(lambda: (lambda v: (v["values"]["cell.scale"] == 2.0, v))(
        api.expect(200, "GET", "/values?refs=cell.scale")), "cell.scale written")
    # level := (scans MOD 100) * scale, both read from one scan.
    def scaled():
        v = api.expect(200, "GET", "/values?refs=cell.level,cell.scans")["values"]
        return v["cell.level"] == (v["cell.scans"] % 100) * 2.0, v
    peerlib.wait_until(scaled, "cell.level = (cell.scans MOD 100) * 2.0")
    before = api.expect(200, "GET", "/values?refs=cell.scans")["values"]["cell.scans"]
    api.expect(200, "PUT", "/tags/cell.scans", {"value": 1000000}, what="a variable the program counts on from")
    peerlib.wait_until(lambda: (lambda v: (v >= 1000000, v))(mb.read_values(100, ["DINT"], table="input")[0]),
                       "cell.scans counting on from 1000000 (was %d)" % before)
    ev = api.expect(200, "GET", "/events?kind=hmi-write")["events"]
    assert any("cell.scale := 2 (by erik)" in e["message"] for e in ev), ev

    # The historian records the tag: points, read with the sqlite3 shell.
    def points():
        out = subprocess.run(["sqlite3", "-readonly", DB,
                              "SELECT count(*), max(p.max) FROM trend_point p JOIN trend_series s ON s.id = p.series "
                              "WHERE s.tag = 'scans_shown'"], capture_output=True, text=True, timeout=30)
        if out.returncode != 0:
            return False, out.stderr
        n, top = out.stdout.strip().split("|")
        return int(n) >= 3 and float(top) > first, out.stdout
    peerlib.wait_until(points, "trend points of scans_shown in the database", timeout=30)
    srv.stop()
    print("ST variables: on the Modbus map, over HTTP and in the historian through their tags")


if __name__ == "__main__":
    main()
