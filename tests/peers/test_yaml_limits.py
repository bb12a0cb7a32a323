"""A project of nested YAML aliases ("billion laughs": 600 bytes that expand
to 10^8 nodes) sent to a real `syncplc run` over HTTP, from Python's own
http.client: POST /api/v1/projects/check and /load refuse it with the
uploaded file's name, line and column, so does /projects/reload of the
instance's own file turned into one, the PLC runs on, and the refused
loads add next to nothing to its peak memory. The run's address space is capped (except under a sanitizer,
which reserves terabytes for its shadow), so that a loader that expands the
aliases fails here rather than the machine.

    /usr/bin/python3 tests/peers/test_yaml_limits.py build/syncplc
"""

import http.client
import json
import mmap
import os
import resource
import subprocess
import tempfile

import peerlib

BINARY = peerlib.syncplc_binary()
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
PASSWORD = "erik-secret-3"
BOUND_KB = 50 * 1024  # what the refused loads may add to the PLC's peak; the expansion would take gigabytes


def sanitized(path):
    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
        return any(m.find(s) >= 0 for s in (b"__asan_init", b"__tsan_init", b"__msan_init"))


def laughs():
    """As tests/project/test_yaml_limits.cpp: refused at line 5, column 45 (line 4 without the task line)."""
    s = "l0: &l0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n"
    for i in range(1, 8):
        a = "*l%d" % (i - 1)
        s += "l%d: &l%d [%s]\n" % (i, i, ", ".join([a] * 10))
    return s


REFUSED = "alias *l2 expands the file past its limit of 10000 YAML nodes"


def vm_hwm_kb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return -1


class Api:
    def __init__(self, port):
        self.port = port
        self.token = None

    def call(self, method, path, body=None):
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
        h = {"Content-Type": "application/json"}
        if self.token:
            h["Authorization"] = "Bearer " + self.token
        c.request(method, "/api/v1" + path, body=json.dumps(body).encode() if body is not None else None, headers=h)
        r = c.getresponse()
        text = r.read().decode("utf-8", "replace")
        c.close()
        return r.status, (json.loads(text) if text else None)

    def expect(self, status, method, path, body=None):
        got, j = self.call(method, path, body)
        if got != status:
            raise AssertionError("%s %s: expected HTTP %d, got %d %r" % (method, path, status, got, j))
        return j


def main():
    if not sanitized(BINARY):
        cap = 2 << 30
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))  # inherited by the syncplc processes below
    p = subprocess.run([BINARY, "user", "add", "erik", "--role", "engineer", "--password-stdin", "--db", DB],
                       input=PASSWORD + "\n", text=True, capture_output=True, timeout=60)
    assert p.returncode == 0, p.stdout + p.stderr

    project_dir = tempfile.mkdtemp(prefix="syncplc-laughs-")
    project = os.path.join(project_dir, "plant.yaml")
    good = ("project: {name: plant, version: 1.0.0}\ntasks: [{name: main, period: 2ms}]\n"
            "tags: [{name: level, type: LREAL, init: 3.5, hmi: read}, {name: out, type: LREAL, hmi: read}]\n"
            "blocks: [{name: m, type: MOVE}]\nconnections: [level -> m.IN, m.OUT -> out]\n")
    with open(project, "w") as f:
        f.write(good)
    srv = peerlib.Server(BINARY, project, extra=["--http", "127.0.0.1:0", "--db", DB])
    api = Api(srv.http_port())
    api.token = api.expect(200, "POST", "/login", {"user": "erik", "password": PASSWORD})["token"]
    hwm_running = vm_hwm_kb(srv.proc.pid)  # the PLC's own peak so far (a sanitizer's shadow included)

    def refused(j, where):
        assert j["ok"] is False and len(j["errors"]) == 1, j
        assert j["errors"][0]["where"] == where, (j, where)
        assert REFUSED in j["errors"][0]["message"], j

    main_laughs = "tasks: [{name: main, period: 2ms}]\n" + laughs()
    included = "include: [more.yaml]\ntasks: [{name: main, period: 2ms}]\n"
    for path in ("/projects/check", "/projects/load"):
        refused(api.expect(400, "POST", path, {"main": "main.yaml", "files": {"main.yaml": main_laughs}}), "main.yaml:5:45")
        refused(api.expect(400, "POST", path, {"main": "main.yaml", "files": {"main.yaml": included, "more.yaml": laughs()}}),
                "more.yaml:4:45")

    # The instance's own file, reloaded over HTTP.
    with open(project, "w") as f:
        f.write(main_laughs)
    status, j = api.call("POST", "/projects/reload", {})
    assert status >= 400 and j["ok"] is False, (status, j)
    assert len(j["errors"]) == 1 and j["errors"][0]["where"] == project + ":5:45", j
    assert REFUSED in j["errors"][0]["message"], j

    # The PLC runs on, unchanged, and never took much memory.
    st = api.expect(200, "GET", "/status")
    assert st["runtime"]["program"] == "plant" and st["tasks"][0]["state"] == "running", st
    before = st["tasks"][0]["scans"]
    peerlib.wait_until(lambda: (api.expect(200, "GET", "/status")["tasks"][0]["scans"] > before + 10, None), "scans go on")
    hwm = vm_hwm_kb(srv.proc.pid)
    assert 0 < hwm_running and hwm - hwm_running < BOUND_KB, "peak RSS of syncplc run: %d kB before, %d kB after" % (
        hwm_running, hwm)
    srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
