"""100 online changes of the four-axis demo while it runs in real time.

`syncplc run` of a copy of projects/four_axis_table/sync.yaml (its `err` and
`pos` tags given Modbus places, `hmi: read`), a pymodbus client reading the
four tracking errors as fast as it can on one connection the whole time, and
`syncplc reload` called 100 times, each after editing the file: a comment,
then an added block instance, then the same instance removed, in turn.

Checks:
- every reload is accepted; the controllers, estimators and both drivers are
  kept (their state: the reference time base, the plant);
- the client's one connection is never dropped and every read is answered;
- the tracking error trace is continuous across each reload: of the reloads
  during which the servo task ran every scan on time, no more than 3 see,
  between two reads that span it, a change larger than ten times the 99th
  percentile of the changes between reads that span none (a reference or
  plant that restarted would jump at every reload, by the whole error). A
  scan the host stalled into an overrun or a skipped grid point makes such a
  jump on its own, with or without a reload (run with RELOADS 0 for the same
  count over 100 windows of the same length): the servo's overruns and
  skipped counts, read from `GET /api/v1/status` after each window, set
  aside the windows in which they grew (since the previous window's end) and
  the windows after those (a skipped 1 ms grid point moves the reference
  by up to 12.6 mrad at the demo's top speed, and the controller takes a
  while to pull the error back); at least 50 windows must be left to judge;
- no scan is late because of a reload: at most 3 of the 100 switches see the
  first scan of the new program start more than 500 us after its release
  (`run` measures it and the report says it), for the same reason.
The servo task's own statistics are printed, not judged: the host's stalls
skip scans with or without reloads (bench/reload_bench.sh compares).

It prints the max start jitter, so that a run with reloads can be compared
with one without (bench/reload_bench.sh; docs/benchmarks.md section 7).

    /usr/bin/python3 tests/reload/test_reloads.py build/syncplc [RELOADS [SECONDS]]

With RELOADS 0 it runs the same setup for SECONDS without a reload (the
benchmark's baseline) and checks only the statistics.
"""

import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
import peerlib as P  # noqa: E402

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "projects", "four_axis_table")
EXTRA = "  - {name: spare, type: ADD, inputs: {IN1: 1.0, IN2: 2.0}}\n"


def make_project(tmp):
    for f in ("sync.yaml", "table.yaml", "table.st"):
        shutil.copy(os.path.join(SRC, f), os.path.join(tmp, f))
    table = os.path.join(tmp, "table.yaml")
    text = open(table).read()
    text = text.replace('{name: pos, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read,',
                        '{name: pos, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read, '
                        'modbus: {table: input_register, address: 100},')
    text = text.replace('{name: err, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read,',
                        '{name: err, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read, '
                        'modbus: {table: input_register, address: 200},')
    if "address: 200" not in text or "address: 100" not in text:
        raise AssertionError("table.yaml no longer declares pos and err as this test expects")
    # This test is about reloads, and measures their effect on the scans
    # itself (switch lateness, overruns): a watchdog of 3 x 1 ms would stop the
    # task at a stall of the machine instead. Under ASan (no mlockall, so a
    # scan can page-fault) one scan of 3.38 ms in a 40 s run did that once.
    watchdog = "watchdog: {time: 1ms, sensitivity: 3, action: safe_stop}"
    if watchdog not in text:
        raise AssertionError("table.yaml no longer has the watchdog this test relaxes")
    text = text.replace(watchdog, "watchdog: {time: 50ms, sensitivity: 3, action: safe_stop}")
    open(table, "w").write(text)
    return os.path.join(tmp, "sync.yaml")


def edit(path, k):
    text = open(path).read().replace(EXTRA, "")
    text = re.sub(r"# reload \d+\n", "", text)
    text += "# reload %d\n" % k
    if k % 3 == 1:
        text = text.replace("blocks:\n", "blocks:\n" + EXTRA, 1)
    open(path, "w").write(text)


class Reader(threading.Thread):
    """Reads err[1..4] (16 input registers) in a loop; keeps (time, values)."""

    def __init__(self, port, tally):
        super().__init__(daemon=True)
        self.peer = P.Peer(port, tally, timeout=5)
        self.samples = []
        self.stop = False
        self.error = None

    def run(self):
        try:
            while not self.stop:
                regs = self.peer.read("input", 200, 16)
                t = time.monotonic()
                vals = [struct.unpack(">d", struct.pack(">4H", *regs[4 * i:4 * i + 4]))[0] for i in range(4)]
                self.samples.append((t, vals))
                time.sleep(0.002)
        except Exception as e:  # reported by the main thread
            self.error = e


def servo_stalls(http_port):
    """The servo task's overruns plus skipped grid points so far."""
    with urllib.request.urlopen("http://127.0.0.1:%d/api/v1/status" % http_port, timeout=10) as r:
        status = json.load(r)
    for t in status["tasks"]:
        if t["name"] == "servo":
            return t["overruns"] + t["skipped"]
    raise AssertionError("no task servo in GET /status: %r" % status["tasks"])


def main():
    binary = P.syncplc_binary()
    reloads = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    plain_seconds = float(sys.argv[3]) if len(sys.argv) > 3 else 10.0
    tmp = tempfile.mkdtemp(prefix="syncplc-reloads-")
    pid_file = os.path.join(tmp, "run.pid")
    try:
        project = make_project(tmp)
        tally = P.Tally()
        server = P.Server(binary, project, extra=("--pid-file", pid_file, "--http", "127.0.0.1:0",
                                                  "--db", ":memory:"))
        http_port = server.http_port()
        reader = Reader(server.port, tally)
        try:
            time.sleep(0.5)
            reader.start()
            time.sleep(0.5)
            windows = []
            grew = []  # per window: the servo overran or skipped since the last window's end
            switch_late_us = []
            stalls = servo_stalls(http_port)
            if reloads == 0:
                # The baseline: the same number of windows of the same length
                # as a run of 100 reloads, without reloading.
                for k in range(100):
                    t0 = time.monotonic()
                    time.sleep(plain_seconds / 200)
                    windows.append((t0, time.monotonic()))
                    time.sleep(plain_seconds / 200)
                    now = servo_stalls(http_port)
                    grew.append(now > stalls)
                    stalls = now
            for k in range(reloads):
                edit(project, k)
                t0 = time.monotonic()
                r = subprocess.run([binary, "reload", "--pid-file", pid_file], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=60)
                t1 = time.monotonic()
                windows.append((t0, t1))
                m = re.search(r"the first scans of the new program started at most ([0-9.]+)(ns|us|ms|s)\b", r.stdout)
                if not m:
                    raise AssertionError("reload %d: no switch line in the report:\n%s" % (k, r.stdout))
                scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[m.group(2)]
                switch_late_us.append(float(m.group(1)) * scale)
                if r.returncode != 0 or not r.stdout.startswith("accepted"):
                    raise AssertionError("reload %d: status %d\n%s" % (k, r.returncode, r.stdout))
                for kept in ("ax1 (SYNC_CONTROLLER, task servo): kept", "ref (COSINE_TRAJECTORY, task servo): kept",
                             "n4_a (TAYLOR_ESTIMATOR, task servo): kept", "driver table: kept open",
                             "driver ring: kept open", "task servo: kept"):
                    if kept not in r.stdout:
                        raise AssertionError("reload %d: '%s' missing from the report:\n%s" % (k, kept, r.stdout))
                if reader.error:
                    raise reader.error
                time.sleep(0.03)
                now = servo_stalls(http_port)
                grew.append(now > stalls)
                stalls = now
            time.sleep(0.3)
        finally:
            reader.stop = True
            reader.join(timeout=10)
            reader.peer.close()
            counters = server.stop()
        if reader.error:
            raise AssertionError("the client's reads failed: %r" % reader.error)
        P.check_counters(counters, tally)
        if counters.accepted != 1:
            raise AssertionError("the client connected %d times: its connection was dropped" % counters.accepted)

        # Continuity: the changes between consecutive reads, per reload window
        # and elsewhere.
        s = reader.samples
        pairs = [(ta, tb, max(abs(x - y) for x, y in zip(a, b))) for (ta, a), (tb, b) in zip(s, s[1:])]
        spans = lambda ta, tb: [i for i, (w0, w1) in enumerate(windows) if ta <= w1 and tb >= w0]
        elsewhere = sorted(j for ta, tb, j in pairs if not spans(ta, tb))
        if len(elsewhere) < 100:
            raise AssertionError("too few reads outside the reloads: %d" % len(elsewhere))
        p99 = elsewhere[int(0.99 * (len(elsewhere) - 1))]
        worst = [0.0] * len(windows)
        for ta, tb, j in pairs:
            for i in spans(ta, tb):
                worst[i] = max(worst[i], j)
        stalled = [g or (i > 0 and grew[i - 1]) for i, g in enumerate(grew)]
        judged = [w for w, st in zip(worst, stalled) if not st]
        jumps = sum(1 for w in judged if w > 10 * p99 + 1e-9)
        stalled_jumps = sum(1 for w, st in zip(worst, stalled) if st and w > 10 * p99 + 1e-9)
        print("reads: %d; |delta err| p99 between reads without a reload %.3g rad; windows with a larger jump "
              "than 10x that: %d of the %d in which the servo ran every scan on time (and %d of the %d in which "
              "it overran or skipped)" % (len(s), p99, jumps, len(judged), stalled_jumps, len(worst) - len(judged)))
        if len(judged) < 50:
            raise AssertionError("the servo overran or skipped in %d of %d windows: too few left to judge the "
                                 "reloads' continuity" % (len(worst) - len(judged), len(worst)))
        if reloads:
            late = sum(1 for x in switch_late_us if x > 500)
            print("switches: first new scan late by at most %.1f us (median %.1f us); %d of %d over 500 us"
                  % (max(switch_late_us), sorted(switch_late_us)[len(switch_late_us) // 2], late, reloads))
            if late > 3:
                raise AssertionError("%d of %d switches made a scan more than 500 us late" % (late, reloads))

        out = server.stdout
        m = re.search(r"^\s*servo\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+\S+\s+(\S+)$", out, re.M)
        if not m:
            raise AssertionError("no statistics line for servo:\n" + out)
        scans, overruns, skipped, trips = (int(g) for g in m.groups()[:4])
        print("servo: %d scans, %d overruns, %d skipped, %d watchdog trips; start jitter min/mean/p99/max %s"
              % (scans, overruns, skipped, trips, m.group(5)))
        # The bound does not grow with the overruns and skips: the windows in
        # which the servo stalled are set aside, not given a looser bound, so a
        # reload that jumps on a busy machine still fails in the windows left.
        if reloads and jumps > 3:
            raise AssertionError("the tracking error jumps at %d of %d reloads during which the servo ran every "
                                 "scan on time (worst %.3g rad against p99 %.3g)" % (jumps, len(judged),
                                                                                  max(judged), p99))
        print("test_reloads: OK (%d reloads)" % reloads)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
