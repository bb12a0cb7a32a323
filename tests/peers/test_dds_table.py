"""The four-axis table on five DDS nodes (projects/four_axis_dds/,
docs/four-axis-dds.md), each node its own `syncplc run --align 1ms` on
loopback with a DDS domain of this test's own, read over each node's HTTP
API:

(a) the axes track: the master's Track-RSME and Sync-RSME over one cosine
    period are below bounds (3 times those of the in-process ring), every
    window scan counted once, enough of them with all four samples;
(b) the master killed with SIGKILL while the axes move fast: every axis
    node sees `ref` stale (ref_ok FALSE, the reaction on) and quick-stops
    its axis: velocity 0, position constant over several reads, the four
    axes within a fraction of a radian of each other;
(c) the master started again: every axis follows it again without a
    restart of its own (same process, the master's samples counted again
    from its new scan 0), and the axes move on the new master's reference
    with small true errors.

Run alone (RUN_SERIAL in tests/CMakeLists.txt): five processes at 1 ms.

Count conditions only; the polling deadlines are generous guards against a hang.

  /usr/bin/python3 tests/peers/test_dds_table.py build/syncplc
"""
import atexit
import os
import shutil
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROJECT = os.path.join(ROOT, "projects", "four_axis_dds")
DOMAIN = 200 + os.getpid() % 30
AXES = ["axis1", "axis2", "axis3", "axis4"]
# The in-process ring's one-period errors (docs/results.md), times 3: the
# nodes measured here 0.057 / 0.055 rad (docs/four-axis-dds.md); the margin
# is for a loaded machine, where late samples are estimated.
TRACK_BOUND = 3 * 0.0589
SYNC_BOUND = 3 * 0.0558
# The ref subscription's stale_after (axis1..4.yaml): the bound printed below.
STALE_AFTER = 50


class Node:
    def __init__(self, binary, tmp, name, tag=""):
        self.name = name
        self.server = peerlib.Server(binary, os.path.join(PROJECT, name + ".yaml"),
                                     extra=("--align", "1ms", "--http", "127.0.0.1:0", "--http-anonymous-read", "on",
                                            "--db", os.path.join(tmp, name + tag + ".db"),
                                            "--set", "net.domain=%d" % DOMAIN))
        self.api = peerlib.HttpApi(self.server.http_port())

    def values(self, *refs):
        try:
            return self.api.expect(200, "GET", "/values?refs=" + ",".join(refs))["values"]
        except OSError:
            self.check_alive()
            raise

    def check_alive(self):
        p = self.server.proc
        if p.poll() is not None:
            raise AssertionError("%s ended (status %d):\n%s\n%s" % (self.name, p.returncode, p.stdout.read(),
                                                                   "".join(self.server.stderr_lines)))

    def scans(self):
        """The task's scans since the process started (GET /status)."""
        return self.api.expect(200, "GET", "/status")["tasks"][0]["scans"]

    def until(self, pred, what, *refs, timeout=60):
        return peerlib.wait_until(lambda: (lambda v: (pred(v), v))(self.values(*refs)), "%s: %s" % (self.name, what),
                                  timeout=timeout, interval=0.02)[0]


def main():
    binary = peerlib.syncplc_binary()
    tmp = tempfile.mkdtemp(prefix="dds-table-")
    atexit.register(shutil.rmtree, tmp, True)
    axes = [Node(binary, tmp, name) for name in AXES]
    master = Node(binary, tmp, "master")

    # (a) One cosine period in the master's window: the axes track and stay in sync.
    r = master.until(lambda v: v["window_done"], "the metrics window completes",
                     "window_done", "track_rsme", "sync_rsme", "samples", "skipped", "window_scans", "cos_start",
                     timeout=120)
    print("window: Track-RSME %.4f rad, Sync-RSME %.4f rad, %d samples, %d skipped, cosine from master scan %d"
          % (r["track_rsme"], r["sync_rsme"], r["samples"], r["skipped"], r["cos_start"]))
    peerlib.check_true(r["samples"] + r["skipped"] == r["window_scans"], "every window scan is counted once: %r" % r)
    # On a loaded machine samples come late (Cyclone's own receive threads
    # run at normal priority): fewer scans have all four fresh; enough must.
    peerlib.check_true(r["samples"] >= 1000, "enough window scans have all four samples: %r" % r)
    peerlib.check_true(0 < r["track_rsme"] < TRACK_BOUND, "Track-RSME below %.4f rad: %r" % (TRACK_BOUND, r))
    peerlib.check_true(0 < r["sync_rsme"] < SYNC_BOUND, "Sync-RSME below %.4f rad: %r" % (SYNC_BOUND, r))

    # (b) Kill the master near the cosine's peak speed (4 pi rad/s at a
    # quarter period) of its second period: the axes move fast.
    start = r["cos_start"]
    master.until(lambda v: v["master_scan"] >= start + 6283 + 1300, "the second period's fast part", "master_scan",
                 timeout=60)
    moving = [a.values("vel[1]", "following", "ref_scan", "quick_stops") for a in axes]
    for a, v in zip(axes, moving):
        peerlib.check_true(v["following"] and abs(v["vel[1]"]) > 5, "%s moves fast before the kill: %r" % (a.name, v))
    old_scan = max(v["ref_scan"] for v in moving)
    scans_before = [a.scans() for a in axes]
    killed = time.monotonic()
    master.server.proc.send_signal(signal.SIGKILL)
    for a in axes:
        a.until(lambda v: not v["ref_ok"] and v["ref_reaction"] and not v["following"], "sees ref stale: quick stop",
                "ref_ok", "ref_reaction", "following", timeout=30)
        print("%s: ref_ok FALSE %.0f ms after SIGKILL (seen by polling every 20 ms; bound: (stale_after %d + 1) "
              "x 1 ms + 1 ms)" % (a.name, 1000 * (time.monotonic() - killed), STALE_AFTER))
    master.server.proc.wait(timeout=30)
    stops = []
    for a, before in zip(axes, moving):
        last = []

        def at_rest(v):
            last.append(v["pos[1]"])
            del last[:-5]  # the last five reads, 20 ms apart at least
            return abs(v["vel[1]"]) < 1e-3 and len(last) == 5 and max(last) - min(last) < 5e-4
        v = a.until(at_rest, "comes to a standstill and stays", "vel[1]", "pos[1]", "v_d", "stop_from", "ref_scan",
                    "quick_stops", timeout=30)
        peerlib.check_true(v["v_d"] == 0.0 and v["quick_stops"] == before["quick_stops"] + 1,
                           "%s: one quick stop, its reference at rest: %r" % (a.name, v))
        print("%s: quick stop from %.4f rad at %.3f rad/s (the master's sample of scan %d the last it took), "
              "stopped at %.4f rad" % (a.name, v["stop_from"][0], v["stop_from"][1], v["ref_scan"], v["pos[1]"]))
        stops.append(v["pos[1]"])
    peerlib.check_true(max(stops) - min(stops) < 0.25, "the four axes stop together: %r" % stops)
    # Still at rest, still stale: the axes hold where they stopped (the
    # controller's slowest mode, about 0.35 s, leaves a tail below 1e-3 rad/s x 0.35 s).
    time.sleep(0.5)
    for a, p in zip(axes, stops):
        v = a.values("pos[1]", "ref_ok", "following")
        peerlib.check_true(abs(v["pos[1]"] - p) < 1e-3 and not v["ref_ok"] and not v["following"],
                           "%s holds its stop position: %r (stopped at %.6f)" % (a.name, v, p))

    # (c) The master again: the same axis processes follow it.
    master2 = Node(binary, tmp, "master", tag="2")
    master2.until(lambda v: v["started"], "hears the four axes and starts", "started", timeout=60)
    for a in axes:
        a.until(lambda v: v["ref_ok"] and v["following"] and v["ref_scan"] < old_scan, "follows the new master",
                "ref_ok", "following", "ref_scan", timeout=60)
    # The references go from where the axes stopped to the cosine's start, all
    # four arriving together; then the cosine runs.
    master2.until(lambda v: v["cosine"] and v["master_scan"] >= v["cos_start"] + 1500, "1.5 s of the new cosine",
                  "cosine", "master_scan", "cos_start", timeout=60)
    for a, p, before in zip(axes, stops, scans_before):
        # The same process: it never ended, and its scans went on counting.
        a.check_alive()
        after = a.scans()
        peerlib.check_true(after > before + 1500, "%s ran on: %d scans, %d before the kill" % (a.name, after, before))
        v = a.values("pos[1]", "vel[1]", "ref_scan", "ref_ok", "following")
        time.sleep(0.1)
        w = a.values("pos[1]", "ref_scan")
        peerlib.check_true(v["following"] and v["ref_ok"], "%s follows: %r" % (a.name, v))
        peerlib.check_true(w["ref_scan"] > v["ref_scan"], "%s counts the new master's samples: %r, %r" % (a.name, v, w))
        peerlib.check_true(abs(v["vel[1]"]) > 1.0 and abs(w["pos[1]"] - v["pos[1]"]) > 0.1,
                           "%s moves on the new reference: %r, %r (stopped at %.4f)" % (a.name, v, w, p))
    for _ in range(10):
        e = master2.values("e_true")["e_true"]
        peerlib.check_true(max(abs(x) for x in e) < 0.2, "the true errors are small again: %r" % e)
        time.sleep(0.05)
    print("restarted master: the axes follow, true errors %s rad" % " ".join("%.4f" % x for x in e))

    master2.server.stop()
    for a in axes:
        a.server.stop()
    print("dds table: OK")


if __name__ == "__main__":
    main()
