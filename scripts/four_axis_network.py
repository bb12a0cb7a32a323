#!/usr/bin/python3
"""Run the four-axis table over Modbus TCP (projects/four_axis_network/):
start four simulated CiA 402 drives (tools/sim_cia402_drive.py --axis 1..4)
on free ports of 127.0.0.1, run `syncplc run` on the project with the ports
passed in (--set bus.devices.dK.port=P), stop the drives at the end (also
on Ctrl-C or an error), and print the motion metrics of paper 000 from the
historian's per-scan points of e_true (the same definitions as
`syncplc sim --metrics`, runtime/project/metrics.hpp) and the age of each
drive's data.

While the PLC runs, the launcher is its operator (docs/four-axis-network.md,
"The safe reaction"): when the table trips (a link lost for the project's
stale tolerance, a drive fault), it holds `restart` (coil 1 of the
project's Modbus map) once every link is ok again, until the four drives
move again, as an operator at the HMI would; each trip and its clearing is
printed. The metrics then count the motion after the last restart.
--no-restart leaves a trip latched.

    scripts/four_axis_network.py [--syncplc build/syncplc] [-d 6.283185s]
        [--project projects/four_axis_network/sync.yaml] [--set inst.param=value]...
        [--metrics out.json] [--keep DIR] [--no-restart]

Only Debian's /usr/bin/python3 sees python3-pymodbus, which the drives need.
"""

import argparse
import json
import math
import os
import signal
import sqlite3
import re
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DRIVE = os.path.join(ROOT, "tools", "sim_cia402_drive.py")
# Scans before the reference starts (the drives' walk to Operation enabled)
# and after it (the run's end) are left out: the metrics count the first
# `duration` of motion.
MARGIN_S = 1.0


def start_drive(axis, extra=()):
    """One drive on a free port; returns (process, port) once it listens."""
    p = subprocess.Popen(["/usr/bin/python3", DRIVE, "--axis", str(axis), "--port", "0", "--max-time", "600", *extra],
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    line = p.stdout.readline()
    if "listening on" not in line:
        p.kill()
        raise RuntimeError("drive %d did not start: %r" % (axis, line))
    return p, int(line.split("listening on ")[1].split()[0].rsplit(":", 1)[1])


def stop(procs):
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(5)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def duration_s(text):
    for suffix, f in (("ms", 1e-3), ("us", 1e-6), ("s", 1.0)):
        if text.endswith(suffix):
            return float(text[:-len(suffix)]) * f
    return float(text)


def series(db, tag):
    """{t: mean} of every per-scan point of a trended tag (element 0 for a scalar)."""
    out = {}
    for label, in db.execute("SELECT label FROM trend_series WHERE tag = ?", (tag,)):
        out[label] = dict(db.execute("SELECT t, mean FROM trend_point p JOIN trend_series s ON p.series = s.id "
                                     "WHERE s.label = ? AND p.level = 0 ORDER BY t", (label,)).fetchall())
    return out


class Operator:
    """Watches the PLC's Modbus map (discrete inputs 0 tripped, 1 moving,
    2 links_ok) and clears a trip as the docs tell an operator to: hold
    `restart` (coil 1) TRUE once every link is ok, until the drives move."""

    def __init__(self, port, restart):
        import logging
        from pymodbus.client import ModbusTcpClient
        # pymodbus logs every refused connection: the PLC's server closes
        # before its process ends, and the watch below says what matters.
        logging.getLogger("pymodbus").setLevel(logging.CRITICAL)
        self.c = ModbusTcpClient("127.0.0.1", port=port, timeout=2, retries=0, retry_on_empty=False)
        self.restart = restart
        self.trips = self.cleared = 0
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self.watch, daemon=True)
        self.thread.start()

    def watch(self):
        holding = False
        was_tripped = False
        while not self.stopping.wait(0.02):
            try:
                if not self.c.connected and not self.c.connect():
                    self.stopping.wait(0.2)  # the PLC not (or no longer) serving: ask again, slowly
                    continue
                r = self.c.read_discrete_inputs(0, 3)
                if r.isError():
                    continue
                tripped, moving, links_ok = r.bits[:3]
                if tripped and not was_tripped:
                    self.trips += 1
                    print("launcher: the table tripped (trip %d)%s" % (self.trips, "" if self.restart else
                          "; --no-restart: it stays latched"), flush=True)
                was_tripped = tripped
                if not self.restart:
                    continue
                if tripped and links_ok and not holding:
                    holding = not self.c.write_coil(1, True).isError()
                    if holding:
                        print("launcher: every link ok again: holding restart", flush=True)
                elif holding and moving and not tripped:
                    if not self.c.write_coil(1, False).isError():
                        holding = False
                        self.cleared += 1
                        print("launcher: moving again: restart released", flush=True)
            except Exception as e:  # the PLC went away (its run ended): nothing left to operate
                if not self.stopping.is_set():
                    print("launcher: Modbus: %s" % e, flush=True)
                self.c.close()

    def stop(self):
        self.stopping.set()
        self.thread.join(5)
        self.c.close()


def motion_start(moving):
    """The first scan of the last stretch of motion: after a trip and its
    restart, the reference starts again from its beginning."""
    t0 = None
    last = False
    for t in sorted(moving):
        m = moving[t] > 0.5
        if m and not last:
            t0 = t
        last = m
    return t0


def metrics(db_path, duration):
    """Track-RSME, Sync-RSME, per-axis max and RMS over the first `duration`
    of scans with `moving` TRUE (after the last restart, when the table
    tripped); the data ages' statistics over the same scans."""
    db = sqlite3.connect(db_path)
    moving = series(db, "moving")["moving"]
    errors = series(db, "e_true")
    labels = ["e_true[%d]" % k for k in range(1, 5)]
    t0 = motion_start(moving)
    if t0 is None:
        raise RuntimeError("the drives never ran: no scan with moving TRUE")
    times = sorted(t for t, v in moving.items() if v > 0.5 and t >= t0)
    # periods: each point is one scan; the first `duration` of motion
    times = [t for t in times if t - t0 < duration * 1e9 - 1e3 and all(t in errors[l] for l in labels)]
    n = len(times)
    track = sync = 0.0
    max_e = [0.0] * 4
    sum_e2 = [0.0] * 4
    max_eps = [0.0] * 4
    for t in times:
        e = [errors[l][t] for l in labels]
        track += sum(x * x for x in e)
        for i in range(4):
            max_e[i] = max(max_e[i], abs(e[i]))
            sum_e2[i] += e[i] * e[i]
            if i:
                eps = e[i] - sum(e[:i]) / i
                sync += eps * eps
                max_eps[i] = max(max_eps[i], abs(eps))
    ages = {}
    for k in range(1, 5):
        a = series(db, "age%d" % k)["age%d" % k]
        v = sorted(a[t] for t in times if t in a)
        mean = sum(v) / len(v)
        ages["d%d" % k] = {"mean_ms": mean, "std_ms": math.sqrt(sum((x - mean) ** 2 for x in v) / len(v)),
                           "p50_ms": v[len(v) // 2], "p99_ms": v[min(len(v) - 1, int(len(v) * 0.99))], "max_ms": v[-1]}
    # The drives sample on their own 1 kHz clocks: a scan may latch the same
    # drive cycle as the scan before (a repeated position) or skip one (a
    # double step). Counted where the reference moves fast (0.5 s .. duration - 0.5 s).
    positions = series(db, "pos")
    sampling = {}
    for k in range(1, 5):
        p = positions.get("pos[%d]" % k, {})
        mid = [t for t in times if 0.5e9 <= t - t0 <= duration * 1e9 - 0.5e9 and t in p]
        steps = [p[b] - p[a] for a, b in zip(mid, mid[1:]) if b - a < 1.5e6]
        repeated = sum(1 for d in steps if d == 0)
        ratios = [b / a for a, b in zip(steps, steps[1:]) if a]
        double = sum(1 for r in ratios if r > 1.6)
        sampling["d%d" % k] = {"steps": len(steps), "repeated": repeated / max(1, len(steps)),
                               "double_or_more": double / max(1, len(ratios))}
    return {
        "samples": n,
        "position_sampling": sampling,
        "track_rsme": math.sqrt(track / n),
        "sync_rsme": math.sqrt(sync / n),
        "axes": [{"axis": i + 1, "max_abs_error": max_e[i], "rms_error": math.sqrt(sum_e2[i] / n),
                  "max_abs_sync_error": max_eps[i]} for i in range(4)],
        "data_age": ages,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--syncplc", default=os.path.join(ROOT, "build", "syncplc"))
    ap.add_argument("--project", default=os.path.join(ROOT, "projects", "four_axis_network", "sync.yaml"))
    ap.add_argument("-d", "--duration", default="6.283185s", help="of motion (the run is %g s longer)" % MARGIN_S)
    ap.add_argument("--set", action="append", default=[], dest="sets")
    ap.add_argument("--metrics", help="write the metrics as JSON here")
    ap.add_argument("--keep", help="keep the PLC database and the outputs in this directory")
    ap.add_argument("--no-restart", action="store_true", help="leave a trip latched (the launcher does not clear it)")
    a = ap.parse_args()
    duration = duration_s(a.duration)
    work = a.keep or tempfile.mkdtemp(prefix="four-axis-network-")
    os.makedirs(work, exist_ok=True)
    db = os.path.join(work, "plc.db")
    for f in (db, db + "-wal", db + "-shm"):
        if os.path.exists(f):
            os.remove(f)
    drives = []
    # SIGTERM ends like Ctrl-C: the finally below stops the drives
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    try:
        ports = []
        for k in range(1, 5):
            p, port = start_drive(k)
            drives.append(p)
            ports.append(port)
        print("drives on 127.0.0.1:" + ", ".join(map(str, ports)), flush=True)
        cmd = [a.syncplc, "run", a.project, "-d", "%gs" % (duration + MARGIN_S), "--no-status", "--db", db]
        for k, port in enumerate(ports, 1):
            cmd += ["--set", "bus.devices.d%d.port=%d" % (k, port)]
        for s in a.sets:
            cmd += ["--set", s]
        print(" ".join(cmd), flush=True)
        env = dict(os.environ, XDG_STATE_HOME=work)
        operator = None
        with open(os.path.join(work, "run.log"), "w") as log:
            plc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.PIPE, text=True, env=env)
            drives.append(plc)  # stopped with the drives on Ctrl-C or an error
            for line in plc.stderr:
                log.write(line)
                log.flush()
                m = re.search(r"modbus: listening on 127\.0\.0\.1:(\d+)", line)
                if m and operator is None:
                    operator = Operator(int(m.group(1)), not a.no_restart)
            rc = plc.wait()
        if operator:
            operator.stop()
            if operator.trips:
                print("launcher: %d trip(s), %d cleared by restart" % (operator.trips, operator.cleared))
        with open(os.path.join(work, "run.log")) as log:
            text = log.read()
        print(text[-3000:])
        if rc != 0:
            print("syncplc run exited with status %d (log in %s)" % (rc, work), file=sys.stderr)
            return rc
    finally:
        stop(drives)
    m = metrics(db, duration)
    m["trips"] = operator.trips if operator else 0
    print("Track-RSME %.6g rad, Sync-RSME %.6g rad over %d scans" % (m["track_rsme"], m["sync_rsme"], m["samples"]))
    for ax in m["axes"]:
        print("  axis %d: max |e| %.4g rad, RMS %.4g rad, max |eps| %.4g rad"
              % (ax["axis"], ax["max_abs_error"], ax["rms_error"], ax["max_abs_sync_error"]))
    for d, s in m["data_age"].items():
        print("  %s data age: mean %.3f ms, std %.3f ms, p50 %.3f ms, p99 %.3f ms, max %.3f ms"
              % (d, s["mean_ms"], s["std_ms"], s["p50_ms"], s["p99_ms"], s["max_ms"]))
    for d, s in m["position_sampling"].items():
        print("  %s position samples: %.1f %% repeated (the same drive cycle as the scan before), %.1f %% steps "
              "over 1.6 times the one before" % (d, 100 * s["repeated"], 100 * s["double_or_more"]))
    if a.metrics:
        with open(a.metrics, "w") as f:
            json.dump(m, f, indent=2)
    try:
        print("load average: %s" % " ".join(open("/proc/loadavg").read().split()[:3]))
    except OSError:
        pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
