"""CIA402_DRIVE fails safe over a real link: `syncplc run` of link_loss.yaml,
its modbus_client driver talking Modbus TCP to the simulated CiA 402 drive
on 127.0.0.1, the axis moving in CSP (an endless cosine, peak 2 rad/s).
Checked (issue 22):

- link lost (the drive stops answering: `silent on`; it still takes the
  requests that reach it, as a drive behind a broken return path would): the
  block commands Quick stop (0002h) at once and holds its last target, never
  the read group's safe value 0; the driver sends the drive nothing while it
  cannot read it (the write gate);
- link back: the drive's first command is that Quick stop; it makes 11 and
  12 (ramp, Switch on disabled) and stays there, motionless, however long,
  until a new enable (enable FALSE, then TRUE) walks it up again (2, 3, 4);
- the statusword group's `_cycles` counts the scans its values are old while
  the drive is silent, and is back to 0..2 when it answers again;
- no target step at any time: the drive itself measures the largest change
  of its target position 607Ah between two of its cycles in Operation
  enabled (the first against the actual position): at most what the
  commanded motion allows.

Waits are for conditions (states, counts of the drive's own 1 kHz cycles);
times only guard against a hang.

    /usr/bin/python3 tests/drives/test_sim_drive_link.py build/syncplc
"""

import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "peers"))

import peerlib  # noqa: E402  (syncplc run on a free port, its own state directory)
from drivelib import REPLY_GUARD, SimDrive, check, client  # noqa: E402

CPR = (1 << 20) / (2 * math.pi)  # counts per rad (the drive's 2^20 counts per revolution)
# The largest target step the commanded motion allows between two drive
# cycles: one scan's worth of the cosine (2 rad/s x 10 ms = 0.02 rad) ten
# times over, for scans a loaded machine delays and bunches. A step to the
# safe value 0 from where the axis is (> 0.8 rad) is 0.8 rad and more.
STEP_BOUND = int(0.2 * CPR)


def main():
    binary = peerlib.syncplc_binary()
    drive = SimDrive("--axis", "1")
    server = peerlib.Server(binary, os.path.join(HERE, "link_loss.yaml"),
                            extra=("--set", "bus.devices.d.port=%d" % drive.port))
    hmi = client(server.port)

    def reg(address, count=1):
        return hmi.read_holding_registers(address, count, slave=1).registers

    def flags():
        return hmi.read_discrete_inputs(0, 2, slave=1).bits[:2]  # ready, link

    def sw_cycles():
        hi, lo = reg(5, 2)
        return (hi << 16) | lo

    def plc_target():
        hi, lo = reg(2, 2)
        v = (hi << 16) | lo
        return v - (1 << 32) if v & 0x80000000 else v

    def wait(what, pred, guard=REPLY_GUARD):
        end = time.monotonic() + guard
        while not pred():
            if time.monotonic() > end:
                raise AssertionError("timed out waiting for " + what)
            time.sleep(0.005)
        check(True, what)

    def drive_cycles_pass(n, each):
        """Calls each(status) until the drive has run n more of its cycles."""
        start = drive.status()["cycles"]
        while True:
            st = drive.status()
            each(st)
            if st["cycles"] - start >= n:
                return
            time.sleep(0.01)

    wait("the link is up (the statusword group ok)", lambda: flags()[1])
    hmi.write_coil(0, True, slave=1)
    wait("enable: the block walks the drive to Operation enabled", lambda: flags()[0])
    check(drive.status()["transitions"][-3:] == [2, 3, 4], "the drive made 2, 3, 4")
    wait("the axis moves along the cosine past 0.8 rad", lambda: drive.status()["position"] > 0.8)

    wait("sw_cycles 0: a scan shows the reply to its own cycle's request", lambda: sw_cycles() == 0)

    # --- link lost ---
    drive.ok("silent on")
    wait("the block sees the link lost (link_ok FALSE)", lambda: not flags()[1])
    frozen = drive.status()["target"]
    check(reg(0)[0] == 0x0002, "link lost: the block commands Quick stop (0002h), not Enable operation")
    check(reg(1)[0] == 0xFFFF, "state -1 (unknown) while the link is down")
    # The scans until the timeout (50 ms) still ran the cosine; the drive got
    # none of their targets (its exchange was waiting for the reply).
    held = plc_target()
    check(abs(held) > int(0.5 * CPR), "the block holds the target it last commanded (%d counts), not the read "
          "group's safe value 0" % held)
    check(abs(held - frozen) < int(0.3 * CPR), "...close to the drive's last (%d counts)" % frozen)

    # The outage lasts 300 drive cycles: reconnections every 20 ms, each a
    # read that gets no answer; the drive's target never changes meanwhile.
    def unchanged_target(st):
        assert st["target"] == frozen, "a target reached the drive while it could not be read: %d -> %d" % (
            frozen, st["target"])
    drive_cycles_pass(300, unchanged_target)
    check(True, "nothing was written to the drive while the link was down")
    # 300 drive cycles are 30 of the task's 10 ms scans: the statusword shown
    # is that many scans old, and sw_cycles says so.
    n = sw_cycles()
    check(n >= 20, "sw_cycles counts the scans since the last reply's request: %d" % n)

    # --- link back ---
    drive.ok("silent off")
    wait("the link returns", lambda: flags()[1])
    wait("sw_cycles back to a reply of the last scans", lambda: sw_cycles() <= 2)
    wait("the drive quick stops and ends in Switch on disabled",
         lambda: drive.status()["state"] == "Switch on disabled")
    t = drive.status()["transitions"]
    check(t[-2:] == [11, 12], "the drive made 11 (Quick stop), 12 (%s)" % t[-4:])
    stopped_at = drive.status()["position"]

    def motionless(st):
        assert st["state"] == "Switch on disabled", "the drive left Switch on disabled: %s" % st["state"]
        assert abs(st["position"] - stopped_at) < 1e-3, "the axis moved: %.5f -> %.5f" % (
            stopped_at, st["position"])
    drive_cycles_pass(1000, motionless)  # 1 s of the drive's time, 100 scans
    check(True, "enable still TRUE: no motion and no walk up without a new enable")
    check(reg(0)[0] == 0x0002 and not flags()[0], "the block keeps commanding Quick stop")

    # --- a new enable ---
    hmi.write_coil(0, False, slave=1)
    wait("enable FALSE seen with the link up (controlword 0000h)", lambda: reg(0)[0] == 0x0000)
    hmi.write_coil(0, True, slave=1)
    wait("the new enable walks the drive up again", lambda: flags()[0])
    check(drive.status()["transitions"][-3:] == [2, 3, 4], "the drive made 2, 3, 4")
    wait("the axis moves again, from where it stopped",
         lambda: abs(drive.status()["position"] - stopped_at) > 0.2)

    worst = drive.status()["max_target_step"]
    check(worst <= STEP_BOUND, "no target step at any time: the largest change of 607Ah between two drive cycles "
          "was %d counts (%.4f rad; bound %d)" % (worst, worst / CPR, STEP_BOUND))
    hmi.write_coil(0, False, slave=1)
    hmi.close()
    drive.stop()
    server.stop()
    events = subprocess.run([binary, "events", "--kind", "driver-fault"], capture_output=True, text=True,
                            timeout=60).stdout
    check("CIA402_DRIVE: link lost" in events, "the link loss is in the PLC's event log")


if __name__ == "__main__":
    main()
