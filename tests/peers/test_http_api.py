"""The HTTP API (docs/http-api.md) of a real `syncplc run`, from Python's own
http.client and Debian's python3-pymodbus: logins and roles, a write read
back over Modbus, a force that holds against the program, project check,
load and rollback, events, the live stream, and hostile requests.

    /usr/bin/python3 tests/peers/test_http_api.py build/syncplc
"""

import http.client
import json
import os
import socket
import subprocess
import time

import peerlib

BINARY = peerlib.syncplc_binary()
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
USERS = {"vera": ("viewer", "vera-secret-1"), "olga": ("operator", "olga-secret-2"), "erik": ("engineer", "erik-secret-3")}


def add_user(name, role, password):
    peerlib.add_user(BINARY, DB, name, role, password)


class Api(peerlib.HttpApi):
    def login(self, user):
        self.token = None
        j = self.expect(200, "POST", "/login", {"user": user, "password": USERS[user][1]}, what="login " + user)
        assert j["role"] == USERS[user][0] and j["user"] == user and j["expires_in_s"] > 0, j
        self.token = j["token"]


def values(api, *refs):
    return api.expect(200, "GET", "/values?refs=" + ",".join(refs))["values"]


def main():
    for name, (role, password) in USERS.items():
        add_user(name, role, password)
    srv = peerlib.Server(BINARY, peerlib.project("http_api.yaml"), extra=["--http", "127.0.0.1:0", "--db", DB])
    port = srv.http_port()
    api = Api(port)

    # --- reads, anonymous on loopback
    st = api.expect(200, "GET", "/status")
    assert st["runtime"]["program"] == "http_api", st["runtime"]
    names = [t["name"] for t in st["tasks"]]
    assert names == ["main"], names
    main_task = st["tasks"][0]
    assert main_task["period_ns"] == 2_000_000 and main_task["state"] == "running", main_task
    # The HTTP API answers from when it listens, which can be before the
    # task's first jitter sample is published: wait for one.
    peerlib.wait_until(lambda: (lambda j: (sum(j["histogram"]["counts"]) > 0, j))(
        api.expect(200, "GET", "/status")["tasks"][0]["jitter"]), "the main task's jitter histogram")
    tags = api.expect(200, "GET", "/tags?filter=mw_arr")["tags"]
    assert [t["name"] for t in tags] == ["mw_arr", "mw_arr_r"], tags
    assert tags[0]["is_array"] and tags[0]["length"] == 4 and tags[0]["value"] == [1, 2, 3, 4], tags[0]
    assert values(api, "iw_const")["iw_const"] == -1234
    api.expect(404, "GET", "/values?refs=no_such_tag", what="unknown ref")
    blocks = api.expect(200, "GET", "/blocks")["blocks"]
    k_iw = [b for b in blocks if b["name"] == "k_iw"][0]
    assert k_iw["type"].startswith("MOVE") and [p["name"] for p in k_iw["pins"]][:2] == ["IN", "OUT"], k_iw

    # --- nothing that changes the PLC without a login
    for method, path, body in [("PUT", "/tags/qw_int", {"value": 5}), ("POST", "/forces", {"ref": "iw_const", "value": 1}),
                               ("DELETE", "/forces/iw_const", None), ("DELETE", "/forces", None),
                               ("POST", "/projects/check", {"main": "a.yaml", "files": {"a.yaml": "x: 1"}}),
                               ("POST", "/projects/load", {"main": "a.yaml", "files": {"a.yaml": "x: 1"}}),
                               ("POST", "/projects/reload", {}), ("POST", "/projects/rollback", {"version": 1})]:
        api.expect(401, method, path, body, what="anonymous")
    api.expect(401, "POST", "/login", {"user": "olga", "password": "wrong-password"}, what="wrong password")
    api.expect(401, "POST", "/login", {"user": "nobody", "password": "whatever-pw"}, what="unknown user")
    api.expect(400, "POST", "/login", {"user": "olga"}, what="no password")

    # --- a viewer reads only
    api.login("vera")
    api.expect(403, "PUT", "/tags/qw_int", {"value": 5}, what="viewer write")
    assert api.expect(200, "GET", "/me") == {"user": "vera", "role": "viewer"}

    # --- an operator's write reaches the program and comes back over Modbus
    api.login("olga")
    j = api.expect(200, "PUT", "/tags/qw_int", {"value": 1234})
    assert j["ok"] and j["task"] == "main", j
    mb = peerlib.pymodbus_client(srv.port)
    peerlib.wait_until(lambda: (lambda r: (not r.isError() and r.registers == [1234], r))(mb.read_holding_registers(10, 1, slave=1)),
                       "qw_int_r over Modbus after the HTTP write")
    api.expect(200, "PUT", "/tags/mw_arr[2]", {"value": 7})
    peerlib.wait_until(lambda: (values(api, "mw_arr_r")["mw_arr_r"] == [1, 2, 7, 4], values(api, "mw_arr_r")), "mw_arr_r")
    api.expect(200, "PUT", "/tags/mw_arr", {"value": [9, 8, 7, 6]})
    peerlib.wait_until(lambda: (values(api, "mw_arr_r")["mw_arr_r"] == [9, 8, 7, 6], values(api, "mw_arr_r")), "whole array")
    e = api.expect(400, "PUT", "/tags/qw_int", {"value": "twelve"})
    assert "qw_int" in e["error"], e
    api.expect(400, "PUT", "/tags/qw_int", {"value": 70000}, what="out of INT's range")
    api.expect(400, "PUT", "/tags/mw_arr", {"value": [1, 2]}, what="array of the wrong length")
    api.expect(404, "PUT", "/tags/mw_arr[9]", {"value": 1}, what="index out of bounds")
    e = api.expect(409, "PUT", "/tags/qw_int_r", {"value": 1}, what="written by the program")
    assert "written by the program" in e["error"] and "force" in e["error"], e
    api.expect(403, "PUT", "/tags/pos[1]", {"value": 1}, what="hmi: read")
    api.expect(404, "PUT", "/tags/nope", {"value": 1})
    api.expect(403, "POST", "/forces", {"ref": "iw_const", "value": 77}, what="operator force")

    # --- an engineer's force holds against the program (k_iw writes -1234 every scan)
    api.login("erik")
    j = api.expect(200, "POST", "/forces", {"ref": "iw_const", "value": 77})
    assert j["ref"] == "iw_const" and j["value"] == "77", j
    peerlib.wait_until(lambda: (lambda r: (not r.isError() and r.registers == [77], r))(mb.read_input_registers(4, 1, slave=1)),
                       "the forced input register")
    for _ in range(20):
        r = mb.read_input_registers(4, 1, slave=1)
        assert not r.isError() and r.registers == [77], r
        time.sleep(0.01)
    t = api.expect(200, "GET", "/tags/iw_const")
    assert t["forced"] is True and t["value"] == 77, t
    assert api.expect(200, "GET", "/forces")["forces"] == [{"ref": "iw_const", "value": "77", "task": "main"}]
    assert api.expect(200, "GET", "/status")["forces"] == 1
    api.expect(400, "POST", "/forces", {"ref": "iw_const", "value": "lots"}, what="bad force value")
    api.expect(404, "POST", "/forces", {"ref": "nope", "value": 1}, what="force of nothing")
    api.expect(200, "DELETE", "/forces/iw_const")
    api.expect(404, "DELETE", "/forces/iw_const", what="unforce of what is not forced")
    peerlib.wait_until(lambda: (lambda r: (not r.isError() and r.registers == [0x10000 - 1234], r))(mb.read_input_registers(4, 1, slave=1)),
                       "the program's value back after unforce")
    mb.close()

    # --- projects: a check with an error at its line, nothing changed; a load; a rollback
    here = os.path.dirname(os.path.abspath(__file__))
    main_text = open(os.path.join(here, "http_api.yaml")).read()
    # The tags in an include of their own, to see errors named by the included file.
    split = main_text.index("tags:"), main_text.index("blocks:")
    common = main_text[split[0]:split[1]]
    main_text = main_text[:split[0]] + "include: [tags.yaml]\n" + main_text[split[1]:]
    bad = common.replace("LREAL", "LREEL", 1)
    line = bad[:bad.index("LREEL")].count("\n") + 1
    col = bad.index("LREEL") - bad.rfind("\n", 0, bad.index("LREEL"))
    before = api.expect(200, "GET", "/status")["tasks"][0]["scans"]
    j = api.expect(400, "POST", "/projects/check", {"main": "main.yaml", "files": {"main.yaml": main_text, "tags.yaml": bad}})
    assert j["ok"] is False and len(j["errors"]) == 1, j
    assert j["errors"][0]["where"] == "tags.yaml:%d:%d" % (line, col), (j, line, col)
    assert "LREEL" in j["errors"][0]["message"], j
    j = api.expect(400, "POST", "/projects/load", {"main": "main.yaml", "files": {"main.yaml": main_text, "tags.yaml": bad}})
    assert j["errors"][0]["where"].startswith("tags.yaml:"), j
    peerlib.wait_until(lambda: (api.expect(200, "GET", "/status")["tasks"][0]["scans"] > before + 10, None), "scans go on")
    assert api.expect(200, "GET", "/status")["runtime"]["program_version"] == "1.0.0"
    api.expect(200, "POST", "/projects/check", {"main": "main.yaml", "files": {"main.yaml": main_text, "tags.yaml": common}})
    newer = main_text.replace("version: 1.0.0", "version: 1.0.1")
    j = api.expect(200, "POST", "/projects/load", {"main": "main.yaml", "files": {"main.yaml": newer, "tags.yaml": common}})
    assert j["ok"] and "k_iw" in j["report"]["kept"] and not j["report"]["new"], j
    loaded = j["version"]
    assert isinstance(loaded, int) and loaded >= 2, j
    assert api.expect(200, "GET", "/status")["runtime"]["program_version"] == "1.0.1"
    assert values(api, "mw_arr_r")["mw_arr_r"] == [9, 8, 7, 6], "tag values carried over the load"
    versions = peerlib.wait_until(lambda: (lambda v: (len(v) >= 2, v))(api.expect(200, "GET", "/projects")["versions"]),
                                  "the upload in the project store")[0]
    assert [v["origin"] for v in versions][:1] == ["run"] and versions[-1]["origin"] == "upload", versions
    assert versions[-1]["running"] and versions[-1]["outcome"] == "accepted", versions[-1]
    assert versions[-1]["version"] == loaded, (versions[-1], loaded)
    j = api.expect(200, "POST", "/projects/rollback", {"version": versions[0]["version"]})
    assert j["ok"] and j["version"] == loaded + 1, (j, loaded)
    assert api.expect(200, "GET", "/status")["runtime"]["program_version"] == "1.0.0"
    api.expect(404, "POST", "/projects/rollback", {"version": 999}, what="rollback to a version that is not there")
    api.expect(200, "POST", "/projects/reload", {})

    # --- the event log names the user and the client
    def logged(kind, text):
        ev = api.expect(200, "GET", "/events?kind=" + kind + "&limit=50")["events"]
        return any(text in e["message"] and e["client"].startswith("127.0.0.1:") for e in ev), ev
    for kind, text in [("reload-failed", "upload of main.yaml by erik rejected:\ntags.yaml:"), ("hmi-write", "qw_int := 1234 (by olga)"), ("force", "forced iw_const to 77 (by erik)"),
                       ("unforce", "unforced iw_const"), ("login", "erik logged in (engineer)"), ("login-failed", "'olga'")]:
        peerlib.wait_until(lambda: logged(kind, text), "event %s %r" % (kind, text))
    peerlib.wait_until(lambda: (lambda ev: (any(e["source"].startswith("uploaded by erik") or "upload" in e["message"]
                                                for e in ev), ev))(api.expect(200, "GET", "/events?kind=reload")["events"]),
                       "the load's reload event")

    # --- the historian: qw_int_r every 100 ms, its points as the page plots them
    def trend():
        j = api.expect(200, "GET", "/trends?tag=qw_int_r&points=50")
        return len(j["points"]) >= 3 and j["points"][-1]["max"] == 1234, j
    j = peerlib.wait_until(trend, "trend points of qw_int_r", timeout=30)[0]
    assert len(j["points"]) <= 50 and all(p["min"] <= p["mean"] <= p["max"] and p["count"] > 0 for p in j["points"]), j
    ts = [p["t_ns"] for p in j["points"]]
    assert ts == sorted(ts), ts
    api.expect(404, "GET", "/trends?tag=speed", what="a tag that is not trended")
    api.expect(400, "GET", "/trends?tag=qw_int_r&since=yesterday", what="a time that is not a number")

    # --- the live stream: newest values at the asked rate, each with its quality
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/api/v1/stream?refs=qw_int_r,mw_arr&rate=20")
    r = c.getresponse()
    assert r.status == 200 and r.getheader("Content-Type").startswith("text/event-stream"), r.status
    got, t0 = [], time.monotonic()
    while len(got) < 5:
        ln = r.fp.readline().decode()
        if ln.startswith("data: "):
            got.append(json.loads(ln[6:]))
    elapsed = time.monotonic() - t0
    c.close()
    assert all(g["values"]["qw_int_r"] == 1234 and g["values"]["mw_arr"] == [9, 8, 7, 6] for g in got), got
    # 4 periods of 50 ms after the first: not faster than asked (a loaded
    # machine can only make it slower; the socket's timeout ends a hang)
    assert elapsed > 0.1, elapsed
    # A client that stops reading its stream costs the others nothing: its
    # events are not queued (each tick takes the newest values), and its
    # worker is cut by the write timeout, not another client's.
    stalled = socket.create_connection(("127.0.0.1", port))
    stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    stalled.sendall(b"GET /api/v1/stream?refs=mw_arr,qw_int_r,iw_const,speed,pos&rate=50 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    time.sleep(1.0)
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/api/v1/stream?refs=qw_int_r&rate=20")
    r = c.getresponse()
    t0, n = time.monotonic(), 0
    while n < 40:
        if r.fp.readline().startswith(b"data: "):
            n += 1
    took = time.monotonic() - t0
    c.close()
    stalled.close()
    assert took < 4.0, "40 events at 20 Hz took %.2f s beside a stalled client" % took
    # An unknown ref is answered for itself; the stream goes on with the others.
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/api/v1/stream?refs=nope,qw_int_r&rate=20")
    r = c.getresponse()
    got = []
    while len(got) < 3:
        ln = r.fp.readline().decode()
        assert not ln.startswith("event: error"), ln
        if ln.startswith("data: "):
            got.append(json.loads(ln[6:]))
    c.close()
    assert all("nope" in g["errors"] and g["values"]["qw_int_r"] == 1234 for g in got), got
    assert all(g["quality"]["qw_int_r"]["q"] == "good" for g in got), got
    api.expect(400, "GET", "/stream?refs=qw_int_r&rate=500", what="rate beyond 50")

    # --- hostile requests
    api.expect(400, "PUT", "/tags/qw_int", raw=b"{not json", what="malformed JSON")
    api.expect(415, "PUT", "/tags/qw_int", raw=b"value=5", content_type="application/x-www-form-urlencoded", what="a form")
    api.expect(413, "PUT", "/tags/qw_int", raw=b"{\"value\": \"" + b"x" * (2 << 20) + b"\"}", what="2 MiB body")
    api.expect(403, "GET", "/status", headers={"Host": "evil.example:%d" % port}, what="DNS rebinding")
    api.expect(403, "PUT", "/tags/qw_int", {"value": 1}, headers={"Origin": "http://evil.example"}, what="cross-site")
    for path in ["/../../../../etc/passwd", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2f..%2fetc/passwd"]:
        s, j, resp = api.call("GET", path, absolute=True)
        assert s in (400, 404), (path, s)
    # A slow client that never finishes its request holds nobody up.
    slow = socket.create_connection(("127.0.0.1", port))
    slow.sendall(b"GET /api/v1/status HTTP/1.1\r\nHost: 127.0.0.1\r\n")
    api.expect(200, "GET", "/status", what="beside a slow client")
    # Answered while the slow client's connection is still open: a server
    # that waited for it would have cut it first (its 5 s read timeout).
    # The connection's TCP state, not a time: 1 is ESTABLISHED.
    assert slow.getsockopt(socket.IPPROTO_TCP, socket.TCP_INFO, 1)[0] == 1, "a request waited for a slow client"
    slow.close()
    raw = socket.create_connection(("127.0.0.1", port))
    raw.sendall(b"GARBAGE\r\n\r\n")
    raw.settimeout(10)
    assert raw.recv(100).startswith(b"HTTP/1.1 400"), "a malformed request line"
    raw.close()

    # --- failed logins slow the address down (last: it stays delayed a while)
    api.token = None
    for _ in range(3):
        api.expect(401, "POST", "/login", {"user": "erik", "password": "guess-guess"})
    s, j, resp = api.call("POST", "/login", {"user": "erik", "password": USERS["erik"][1]})
    assert s == 429 and int(resp.getheader("Retry-After")) > 0, (s, j)

    srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
