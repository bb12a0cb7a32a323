"""Live values as subscriptions (docs/http-api.md, "Live values") of a real
`syncplc run`, from Python's own http.client: 300 tags with 41-character
names in one subscription (a URL list cannot carry them: 414 / 400),
references added and dropped while its stream runs, an unknown and an
hmi: none reference answered for themselves while the others go on, and
every value with its quality (good, forced, driver_not_ok, task_stopped) and
the logical time of the scan that made it. A subscription is its session's
alone, and deleting it ends its stream.

    /usr/bin/python3 tests/peers/test_http_live.py build/syncplc
"""

import http.client
import json
import os
import re
import socket
import subprocess
import time

import peerlib

BINARY = peerlib.syncplc_binary()
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
N = 300
NAMES = ["a_tag_with_a_long_name_for_a_big_page_%03d" % i for i in range(N)]  # 41 characters each


def project_text(dead_port):
    tags = "\n".join('  - {name: %s, type: INT, hmi: read, task: main, init: %d}' % (n, i) for i, n in enumerate(NAMES))
    return """project: {name: http_live, version: 1.0.0}
tasks:
  - {name: main, period: 2ms}
  - {name: bad, period: 20ms, watchdog: {time: 1ms, action: stop}}
tags:
%s
  - {name: counter, type: LREAL, hmi: read}
  - {name: held, type: INT, hmi: readwrite, task: main, init: 5}
  - {name: secret, type: INT, task: main}
  - {name: bad_w, type: INT, hmi: read, task: bad, init: 2}
  - {name: remote, type: INT, hmi: read}
blocks:
  - {name: ramp, type: ADD, task: main, inputs: {IN2: 1.0}}
  - {name: z, type: UNIT_DELAY, task: main}
  - {name: load, type: BURN, task: bad, inputs: {EXEC: 5ms}}
connections:
  - ramp.OUT -> counter
  - counter -> z.IN
  - z.OUT -> ramp.IN1
drivers:
  - name: field
    type: modbus_client
    task: main
    devices:
      - {name: gone, host: 127.0.0.1, port: %d, connect_timeout: 50ms, response_timeout: 50ms}
    groups:
      - {name: r, device: gone, function: read_holding_registers, address: 0, count: 1, type: INT}
    bind: {r: remote}
""" % (tags, dead_port)



class Stream:
    """A subscription's Server-Sent Events, read one `values` event at a time."""

    def __init__(self, port, path, token=None):
        self.c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        h = {"Accept": "text/event-stream"}
        if token:
            h["Authorization"] = "Bearer " + token
        self.c.request("GET", path, headers=h)
        self.r = self.c.getresponse()
        self.status = self.r.status

    def next(self):
        """('values', data) or ('error', data)."""
        kind = None
        while True:
            ln = self.r.fp.readline().decode()
            if not ln:
                return ("end", None)
            if ln.startswith("event: "):
                kind = ln[7:].strip()
            elif ln.startswith("data: "):
                return (kind, json.loads(ln[6:]))

    def values_until(self, ok, what, limit=200):
        for _ in range(limit):
            kind, d = self.next()
            assert kind == "values", (kind, d)
            if ok(d):
                return d
        raise AssertionError("no event of the stream showed " + what)

    def close(self):
        self.c.close()


def main():
    subprocess.run([BINARY, "user", "add", "erik", "--role", "engineer", "--password-stdin", "--db", DB],
                   input="erik-secret-3\n", text=True, capture_output=True, timeout=60, check=True)
    path = os.path.join(peerlib.STATE_DIR, "http_live.yaml")
    with open(path, "w") as f:
        f.write(project_text(peerlib.free_port()))
    srv = peerlib.Server(BINARY, path, extra=["--http", "127.0.0.1:0", "--db", DB])
    port = srv.http_port()
    api = peerlib.HttpApi(port)
    try:
        # Stopped by its watchdog, or (a loaded machine stretching its 5 ms burn)
        # given up on by the supervisor as hung: both stop the task.
        peerlib.wait_until(lambda: (any(t["name"] == "bad" and t["state"] in ("stopped", "hung")
                                        for t in api.expect(200, "GET", "/status")["tasks"]), None),
                           "the watchdog stopping task bad", timeout=120)
    except AssertionError:
        print("GET /status:", json.dumps(api.expect(200, "GET", "/status")["tasks"])[:3000])
        print("stderr of syncplc run:\n" + "".join(srv.stderr_lines)[-5000:])
        raise

    # The URL form cannot carry a big page: 300 x 41 characters > 8 KiB.
    status, _, _ = api.call("GET", "/stream?refs=" + ",".join(NAMES))
    assert status in (414, 400), status

    # --- one subscription with all of them, an unknown and a hidden ref among them
    refs = NAMES + ["counter", "bad_w", "remote", "held", "nope", "secret"]
    sub = api.expect(201, "POST", "/subscriptions", {"refs": refs, "rate": 20})
    sid = sub["id"]
    assert sub["stream"] == "/api/v1/subscriptions/%s/stream" % sid, sub
    assert sub["refs"][NAMES[7]] == {"task": "main", "period_ns": 2_000_000, "type": "INT", "length": 1}, sub["refs"][NAMES[7]]
    assert "nope" in sub["refs"]["nope"]["error"], sub["refs"]["nope"]
    assert "hmi: none" in sub["refs"]["secret"]["error"], sub["refs"]["secret"]
    assert sub["refs"]["remote"]["driver"] == "field", sub["refs"]["remote"]

    st = Stream(port, sub["stream"])
    assert st.status == 200, st.status
    d = st.values_until(lambda d: all(n in d["values"] for n in NAMES), "all 300 values")
    assert [d["values"][n] for n in NAMES] == list(range(N)), "the values as loaded"
    assert set(d["errors"]) == {"nope", "secret"}, d.get("errors")
    assert "secret" not in d["values"]
    q = d["quality"]
    assert all(q[n]["q"] == "good" for n in NAMES), [q[n] for n in NAMES if q[n]["q"] != "good"][:3]
    assert q["bad_w"]["q"] == "task_stopped", q["bad_w"]
    assert q["remote"]["q"] == "driver_not_ok", q["remote"]
    # The logical time of the scan: a multiple of the task's 2 ms; its age
    # measured from `now`, read before the values (a scan that published
    # while they were read is newer than `now`: age 0), and young.
    s0 = q["counter"]["scan_ns"]
    assert s0 % 2_000_000 == 0 and s0 > 0, s0
    assert q["counter"]["age_ns"] == max(0, d["now_ns"] - s0), (q["counter"], d["now_ns"])
    assert q["counter"]["age_ns"] < 3 * 2_000_000 + 100_000_000, q["counter"]
    d2 = st.values_until(lambda e: e["quality"]["counter"]["scan_ns"] > s0, "a newer scan")
    assert d2["values"]["counter"] > d["values"]["counter"], (d["values"]["counter"], d2["values"]["counter"])

    # --- views close and open: drop 100, add one; the running stream follows
    j = api.expect(200, "PATCH", "/subscriptions/" + sid, {"drop": NAMES[:100], "add": ["ramp.OUT"]})
    assert len(j["dropped"]) == 100 and j["refs"]["ramp.OUT"]["task"] == "main", j
    d = st.values_until(lambda e: "ramp.OUT" in e["values"] and NAMES[0] not in e["values"], "the change")
    assert all(n in d["values"] for n in NAMES[100:]), "the others stay"
    assert d["quality"]["ramp.OUT"]["q"] == "good"

    # --- a force shows as such
    erik = peerlib.HttpApi(port)
    erik.token = erik.expect(200, "POST", "/login", {"user": "erik", "password": "erik-secret-3"})["token"]
    erik.expect(200, "POST", "/forces", {"ref": "held", "value": 77})
    # (Listed as forced once queued, up to a scan before the task holds it.)
    d = st.values_until(lambda e: e["quality"]["held"]["q"] == "forced" and e["values"]["held"] == 77, "the force")
    assert d["forced"]["held"] is True, d["forced"]
    erik.expect(200, "DELETE", "/forces/held")

    # --- another session cannot see or change it; bad requests are 400 / 404
    erik.expect(404, "GET", "/subscriptions/" + sid, what="someone else's subscription")
    erik.expect(404, "PATCH", "/subscriptions/" + sid, {"add": ["counter"]})
    api.expect(400, "PATCH", "/subscriptions/" + sid, {"add": "counter"}, what="not a list")
    api.expect(400, "PATCH", "/subscriptions/" + sid, {"add": [1, 2]}, what="not strings")
    api.expect(400, "POST", "/subscriptions", {"refs": ["x" * 300]}, what="a reference too long")
    api.expect(400, "POST", "/subscriptions", {"rate": 500}, what="rate beyond 50")
    api.expect(404, "GET", "/subscriptions/0123456789abcdef/stream", what="no such subscription")
    mine = api.expect(200, "GET", "/subscriptions/" + sid)
    assert len(mine["refs"]) == N - 100 + 7, len(mine["refs"])

    # --- an engineer's own subscription sees hmi: none values
    es = erik.expect(201, "POST", "/subscriptions", {"refs": ["secret"]})
    assert es["refs"]["secret"]["type"] == "INT", es
    e_stream = Stream(port, es["stream"], erik.token)
    kind, d = e_stream.next()
    assert kind == "values" and "secret" in d["values"] and "errors" not in d, d
    # Logging out ends the session's subscriptions.
    erik.expect(200, "POST", "/logout")
    kind, d = e_stream.next()
    while kind == "values":
        kind, d = e_stream.next()
    e_stream.close()
    api.expect(404, "GET", "/subscriptions/" + es["id"], what="a logged-out session's subscription")

    # --- deleting a subscription ends its stream
    api.expect(204, "DELETE", "/subscriptions/" + sid)
    kind, d = st.next()
    while kind == "values":
        kind, d = st.next()
    assert kind == "error" and "deleted" in d["error"], (kind, d)
    st.close()
    api.expect(404, "PATCH", "/subscriptions/" + sid, {"add": ["counter"]}, what="a deleted subscription")

    # --- syncplc watch shows the same quality
    env = dict(os.environ, SYNCPLC_URL="http://127.0.0.1:%d" % port)
    p = subprocess.run([BINARY, "watch", "bad_w", "remote", "counter", "--count", "2", "--rate", "20"], env=env,
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, (p.returncode, p.stdout, p.stderr)
    lines = [l for l in p.stdout.splitlines() if "bad_w = 2 (task stopped)" in l and "remote = 0 (driver not ok)" in l]
    assert len(lines) == 2, p.stdout
    assert all(re.search(r"counter = [0-9.e+]+$", l) for l in lines), p.stdout

    srv.stop()
    print("test_http_live: OK")


if __name__ == "__main__":
    main()
