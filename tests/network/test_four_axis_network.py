"""The four-axis table over Modbus TCP (projects/four_axis_network/) against
real processes: four tools/sim_cia402_drive.py drives and `syncplc run`, all
on 127.0.0.1, the test watching through the PLC's Modbus server (the
project's HMI map) and the drives' `status`.

  kill     kill one drive mid-move: its group's ok falls within one response
           timeout, the safe reaction (quick stop) on all axes, events; restart
           it on the same port: reconnection, a fault reset through CiA 402
           (a drive that faulted meanwhile), all four enabled, motion resumes
  mute     one drive accepts but never answers (`silent on`): the other
           drives' data stay fresh (age, every scan, from the historian)

    /usr/bin/python3 tests/network/test_four_axis_network.py build/syncplc kill|mute
"""

import os
import re
import shutil
import signal
import sqlite3
import struct
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "drives"))
import drivelib  # noqa: E402

PROJECT = os.path.join(ROOT, "projects", "four_axis_network", "sync.yaml")
RESPONSE_TIMEOUT = 0.050  # the project's response_timeout
# Slack for a loaded 2-core machine (sanitizer builds, other tests in
# parallel): the bounds are generous, the measured values are printed.
SLACK = 0.5


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def wait_until(fn, what, timeout=10.0, interval=0.002):
    deadline = time.monotonic() + timeout
    while True:
        v = fn()
        if v:
            return v
        if time.monotonic() > deadline:
            raise AssertionError("%s: not within %.1f s" % (what, timeout))
        time.sleep(interval)


class Plc:
    """`syncplc run` of the project, the drives' ports passed in with --set."""

    def __init__(self, binary, ports, work):
        self.db = os.path.join(work, "plc.db")
        args = [binary, "run", PROJECT, "--no-status", "-d", "90s", "--db", self.db]
        for k, port in enumerate(ports, 1):
            args += ["--set", "bus.devices.d%d.port=%d" % (k, port)]
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                     env=dict(os.environ, XDG_STATE_HOME=work))
        drivelib._running.append(self.proc)
        self.out, self.err = [], []
        port = None
        for line in self.proc.stderr:
            self.err.append(line)
            m = re.search(r"modbus: listening on 127\.0\.0\.1:(\d+)", line)
            if m:
                port = int(m.group(1))
                break
        if port is None:
            self.proc.kill()
            raise AssertionError("syncplc run did not start:\n" + "".join(self.err) + self.proc.stdout.read())
        threading.Thread(target=lambda: self.err.extend(self.proc.stderr), daemon=True).start()
        threading.Thread(target=lambda: self.out.extend(self.proc.stdout), daemon=True).start()
        from pymodbus.client import ModbusTcpClient
        self.c = ModbusTcpClient("127.0.0.1", port=port, timeout=5, retries=0, retry_on_empty=False)
        check(self.c.connect(), "cannot connect to the PLC's Modbus server")

    def inputs(self):
        """tripped, moving, links_ok, ok1..ok4"""
        r = self.c.read_discrete_inputs(0, 7)
        check(not r.isError(), "read discrete inputs: %r" % r)
        return r.bits[:7]

    def ages(self):
        r = self.c.read_holding_registers(26, 16)
        check(not r.isError(), "read ages: %r" % r)
        return [struct.unpack(">d", struct.pack(">4H", *r.registers[4 * i:4 * i + 4]))[0] for i in range(4)]

    def restart(self, on):
        check(not self.c.write_coil(1, on).isError(), "write restart")

    def stop(self):
        self.c.close()
        self.proc.send_signal(signal.SIGTERM)
        rc = self.proc.wait(timeout=60)
        time.sleep(0.2)  # the reader threads take the last lines
        out, err = "".join(self.out), "".join(self.err)
        check(rc == 0, "syncplc run exited with %d\n%s\n%s" % (rc, out, err))
        for bad in ("ERROR: AddressSanitizer", "runtime error:", "WARNING: ThreadSanitizer"):
            check(bad not in err, "sanitizer report:\n" + err)
        return out + err  # events are lines on stderr with --no-status

    def age_series(self, k, t_from, t_to):
        """Drive k's data age at every scan in [t_from, t_to] (ns, wall clock), sorted."""
        db = sqlite3.connect(self.db)
        return [r[0] for r in db.execute("SELECT p.max FROM trend_point p JOIN trend_series s ON p.series = s.id "
                                         "WHERE s.label = ? AND p.t BETWEEN ? AND ? ORDER BY p.max",
                                         ("age%d" % k, t_from, t_to))]


def start(binary):
    work = tempfile.mkdtemp(prefix="four-axis-network-test-")
    drives = [drivelib.SimDrive("--axis", str(k), max_time=120) for k in range(1, 5)]
    plc = Plc(binary, [d.port for d in drives], work)
    wait_until(lambda: plc.inputs()[1], "the four drives enabled and moving", timeout=20)
    print("moving: all four drives in Operation enabled (CST)")
    return work, drives, plc


def states(drives, skip=()):
    return [d.status()["state"] for i, d in enumerate(drives) if i not in skip]


def test_kill(binary):
    work, drives, plc = start(binary)
    try:
        time.sleep(0.5)  # mid-move: the cosine is at its fastest near t = pi/2
        x0 = drives[0].status()["position"]
        check(x0 > 0.1, "axis 1 moved: %r" % x0)
        port2 = drives[1].port
        drives[1].p.kill()
        t_kill = time.monotonic()
        drives[1].p.wait()
        wait_until(lambda: not plc.inputs()[4], "ok2 falls after the kill", timeout=5)
        dt = time.monotonic() - t_kill
        print("ok2 FALSE %.1f ms after the kill (response timeout %.0f ms)" % (dt * 1e3, RESPONSE_TIMEOUT * 1e3))
        check(dt < RESPONSE_TIMEOUT + SLACK, "stale within one response timeout (+ slack): %.3f s" % dt)
        bits = wait_until(lambda: (lambda b: b if b[0] else None)(plc.inputs()), "tripped", timeout=2)
        check(not bits[1] and not bits[2], "tripped: not moving, links not ok: %r" % bits)
        # the safe reaction on all axes: every live drive quick-stops (11)
        # and ends in Switch on disabled (12), its power stage off
        live = [0, 2, 3]
        wait_until(lambda: all(s == "Switch on disabled" for s in states(drives, skip=(1,))),
                   "the live drives quick-stopped to Switch on disabled", timeout=5)
        for i in live:
            st = drives[i].status()
            check(11 in st["transitions"] and 12 in st["transitions"], "drive %d: %r" % (i + 1, st))
            check(st["u"] == 0, "drive %d power stage off: %r" % (i + 1, st))
        print("tripped: drives 1, 3, 4 quick-stopped (11, 12) to Switch on disabled")

        # a drive that faulted meanwhile (as a real drive's fieldbus watchdog
        # would: 8130h), cleared below by the restart's fault reset
        drives[2].ok("fault 0x8130")
        wait_until(lambda: drives[2].status()["state"] == "Fault", "drive 3 in Fault", timeout=5)

        # restart drive 2 on the same port: the client reconnects
        drives[1] = drivelib.SimDrive("--axis", "2", "--port", str(port2), max_time=120)
        t_up = time.monotonic()
        wait_until(lambda: plc.inputs()[4], "ok2 again after the restart", timeout=5)
        print("ok2 TRUE %.0f ms after drive 2 listened again" % ((time.monotonic() - t_up) * 1e3))
        time.sleep(0.3)
        check(plc.inputs()[0], "the trip holds until the operator's restart")
        check(states(drives, skip=(2,)) == ["Switch on disabled"] * 3, "nothing enabled before the restart: %r"
              % states(drives))

        plc.restart(True)
        wait_until(lambda: plc.inputs()[1], "moving again after the restart", timeout=10)
        plc.restart(False)
        st3 = drives[2].status()
        check(15 in st3["transitions"] and st3["state"] == "Operation enabled" and st3["error_code"] == 0,
              "drive 3: fault reset (15) through CiA 402, enabled again: %r" % st3)
        check(states(drives) == ["Operation enabled"] * 4, "all four enabled: %r" % states(drives))
        p1 = [d.status()["position"] for d in drives]
        time.sleep(0.5)
        p2 = [d.status()["position"] for d in drives]
        check(all(abs(b - a) > 0.01 for a, b in zip(p1, p2)), "motion resumed on every axis: %r -> %r" % (p1, p2))
        check(not plc.inputs()[0], "the trip cleared")
        print("restart: drive 3's fault reset (15), all four in Operation enabled, all moving")
    finally:
        out = plc.stop()
        for d in drives:
            d.stop()
    for what in ("driver-fault", "modbus_client bus.io2: ", "modbus_client bus.io2: ok again",
                 "CIA402_DRIVE: drive fault", "CIA402_DRIVE: drive fault cleared"):
        check(what in out, "event %r in the run's output:\n%s" % (what, out))
    print("events: the lost connection, the recovery, the drive fault and its reset")
    shutil.rmtree(work, True)


def test_mute(binary):
    work, drives, plc = start(binary)
    try:
        time.sleep(0.3)
        drives[2].ok("silent on")
        t_mute = time.monotonic()
        wait_until(lambda: not plc.inputs()[5], "ok3 falls when drive 3 is mute", timeout=5)
        print("ok3 FALSE %.1f ms after `silent on`" % ((time.monotonic() - t_mute) * 1e3))
        check(time.monotonic() - t_mute < RESPONSE_TIMEOUT + SLACK, "stale within one response timeout (+ slack)")
        t_from = time.time_ns()
        polled = []
        end = time.monotonic() + 1.5  # several timeouts and reconnections of drive 3
        while time.monotonic() < end:
            polled.append(plc.ages())
            time.sleep(0.01)
        t_to = time.time_ns()
        check(not plc.inputs()[5], "drive 3 still stale")
        check(max(a[2] for a in polled) > RESPONSE_TIMEOUT * 1e3, "drive 3's data aged: %r" % polled[-1])
        drives[2].ok("silent off")
        wait_until(lambda: plc.inputs()[5], "ok3 again after `silent off`", timeout=5)
    finally:
        plc.stop()
        for d in drives:
            d.stop()
    # every scan of the mute time, from the historian (age trended per scan)
    for k in (1, 2, 4):
        ages = plc.age_series(k, t_from, t_to)
        n = len(ages)
        check(n > 500, "scans recorded while mute: %d" % n)
        p90, worst = ages[n * 9 // 10], ages[-1]
        print("drive %d: data age over %d scans while drive 3 was mute: p90 %.2f ms, max %.2f ms" % (k, n, p90, worst))
        # A device thread shared with the mute drive would wait out its 50 ms
        # timeout at every exchange: most of these ages would be 50 ms and
        # more. A loaded machine stalls a few scans, not most: the p90 is
        # checked against the timeout, the max only against several of them.
        check(p90 < 20.0, "drive %d's data age stays well below the mute drive's timeout (p90 < 20 ms): %.2f ms" % (k, p90))
        check(worst < 500.0, "drive %d's largest data age %.2f ms" % (k, worst))
    shutil.rmtree(work, True)


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in ("kill", "mute"):
        sys.exit("usage: /usr/bin/python3 %s PATH/TO/syncplc kill|mute" % sys.argv[0])
    {"kill": test_kill, "mute": test_mute}[sys.argv[2]](sys.argv[1])
    print("ok")


if __name__ == "__main__":
    main()
