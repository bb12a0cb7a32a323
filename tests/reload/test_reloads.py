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
- the tracking error trace is continuous across each reload: the largest
  change between two reads that span a reload is within three times the
  largest between reads that do not (the error moves with the trajectory, so
  the two are of the same size; the demo restarting its reference or its
  plant would jump by the whole error, a hundred times more);
- the servo task misses no scan (skipped 0) and its watchdog never trips.

It prints the max start jitter, so that a run with reloads can be compared
with one without (bench/reload_bench.sh; docs/benchmarks.md section 7).

    /usr/bin/python3 tests/reload/test_reloads.py build/syncplc [RELOADS [SECONDS]]

With RELOADS 0 it runs the same setup for SECONDS without a reload (the
benchmark's baseline) and checks only the statistics.
"""

import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
import peerlib as P  # noqa: E402

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "projects", "four_axis_table")
EXTRA = "  - {name: spare, type: ADD, inputs: {IN1: 1.0, IN2: 2.0}}\n"


def make_project(tmp):
    for f in ("sync.yaml", "table.yaml"):
        shutil.copy(os.path.join(SRC, f), os.path.join(tmp, f))
    table = os.path.join(tmp, "table.yaml")
    text = open(table).read()
    text = text.replace('{name: pos, type: "ARRAY[1..4] OF LREAL", unit: rad,',
                        '{name: pos, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read, '
                        'modbus: {table: input_register, address: 100},')
    text = text.replace('{name: err, type: "ARRAY[1..4] OF LREAL", unit: rad,',
                        '{name: err, type: "ARRAY[1..4] OF LREAL", unit: rad, hmi: read, '
                        'modbus: {table: input_register, address: 200},')
    if "address: 200" not in text or "address: 100" not in text:
        raise AssertionError("table.yaml no longer declares pos and err as this test expects")
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


def main():
    binary = P.syncplc_binary()
    reloads = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    plain_seconds = float(sys.argv[3]) if len(sys.argv) > 3 else 10.0
    tmp = tempfile.mkdtemp(prefix="syncplc-reloads-")
    pid_file = os.path.join(tmp, "run.pid")
    try:
        project = make_project(tmp)
        tally = P.Tally()
        server = P.Server(binary, project, extra=("--pid-file", pid_file))
        reader = Reader(server.port, tally)
        try:
            time.sleep(0.5)
            reader.start()
            time.sleep(0.5)
            windows = []
            if reloads == 0:
                time.sleep(plain_seconds)
            for k in range(reloads):
                edit(project, k)
                t0 = time.monotonic()
                r = subprocess.run([binary, "reload", "--pid-file", pid_file], stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=60)
                t1 = time.monotonic()
                windows.append((t0, t1))
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

        # Continuity: the change between consecutive reads across a reload
        # against elsewhere.
        s = reader.samples
        if reloads == 0:
            windows = [(float("inf"), float("inf"))]
        across, elsewhere = [], []
        for (ta, a), (tb, b) in zip(s, s[1:]):
            jump = max(abs(x - y) for x, y in zip(a, b))
            spans = any(ta <= w1 and tb >= w0 for w0, w1 in windows)
            (across if spans else elsewhere).append(jump)
        if reloads and (not across or not elsewhere):
            raise AssertionError("too few reads: %d across reloads, %d elsewhere" % (len(across), len(elsewhere)))
        worst_across, worst_elsewhere = max(across or [0.0]), max(elsewhere)
        print("reads: %d (%d spanning a reload); max |delta err| across a reload %.3g rad, elsewhere %.3g rad"
              % (len(s), len(across), worst_across, worst_elsewhere))
        if worst_across > 3 * worst_elsewhere + 1e-9:
            raise AssertionError("the tracking error jumps at a reload: %.3g rad against %.3g elsewhere"
                                 % (worst_across, worst_elsewhere))

        out = server.stdout
        m = re.search(r"^\s*servo\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+\S+\s+(\S+)$", out, re.M)
        if not m:
            raise AssertionError("no statistics line for servo:\n" + out)
        scans, overruns, skipped, trips = (int(g) for g in m.groups()[:4])
        print("servo: %d scans, %d overruns, %d skipped, %d watchdog trips; start jitter min/mean/p99/max %s"
              % (scans, overruns, skipped, trips, m.group(5)))
        if skipped != 0 or trips != 0:
            raise AssertionError("the servo task missed scans (%d skipped, %d watchdog trips) during %d reloads"
                                 % (skipped, trips, reloads))
        print("test_reloads: OK (%d reloads)" % reloads)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
