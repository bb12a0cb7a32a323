"""The simulated CiA 402 drive's homing mode (6) over Modbus TCP, through a
pymodbus client: method 37 (the current position becomes the home offset),
method 17 (the negative limit switch: search, back off, its edge becomes the
home offset), a homing interrupted by bit 4 falling, and a homing error
(method 18 on a drive without a positive limit switch), with statusword
bits 10, 12, 13 as the homing mode table says.

    /usr/bin/python3 tests/drives/test_sim_drive_homing.py
"""

import math
import time

from drivelib import REPLY_GUARD, Axis, SimDrive, check, sim

K = (1 << 20) / (2 * math.pi)  # counts per rad (the drive's default)
BITS = 0x3400  # bits 13, 12, 10


def homing_bits(a):
    return a.actual()["statusword"] & BITS


def wait_bits(a, want, what):
    end = time.monotonic() + REPLY_GUARD
    while homing_bits(a) != want:
        if time.monotonic() > end:
            raise AssertionError("%s: statusword 16#%04X" % (what, a.actual()["statusword"]))
        time.sleep(0.002)
    check(True, what)


def main():
    d = SimDrive("--negative-limit", "-0.5")
    a = Axis(d.port)
    a.enable(8)
    a.mode(6)
    end = time.monotonic() + REPLY_GUARD
    while a.actual()["mode"] != 6:
        assert time.monotonic() < end, "the display never showed 6"
        time.sleep(0.002)
    check(True, "homing mode (6) is supported: the display shows it")
    wait_bits(a, 0x0400, "before a start: 0 0 1, not started")

    # Method 37: no motion, the position becomes the home offset.
    a.write(sim.HR_HOMING_METHOD, [37])
    a.write(sim.HR_HOME_OFFSET, sim.words32(123456))
    a.controlword(0x1F)
    wait_bits(a, 0x1400, "method 37: 0 1 1, homing completed")
    check(abs(a.actual()["position"] - 123456) <= 1, "the position is the home offset: %d" % a.actual()["position"])
    a.controlword(0x0F)
    wait_bits(a, 0x0400, "bit 4 low again: 0 0 1 (the old attained is not shown)")

    # Method 17 interrupted: bit 4 falls during the search, the drive stops.
    a.write(sim.HR_HOMING_METHOD, [17])
    a.write(sim.HR_HOME_OFFSET, sim.words32(0))
    a.write(sim.HR_HOMING_SPEED_SWITCH, sim.words32(int(1.0 * K)))
    a.write(sim.HR_HOMING_SPEED_ZERO, sim.words32(int(0.1 * K)))
    a.write(sim.HR_HOMING_ACCELERATION, sim.words32(int(20 * K)))
    a.controlword(0x1F)
    wait_bits(a, 0x0000, "method 17: 0 0 0, in progress")
    end = time.monotonic() + REPLY_GUARD
    while d.status()["velocity"] > -0.5:
        assert time.monotonic() < end, "the search does not move in -"
        time.sleep(0.002)
    check(True, "the search moves in - (towards the negative limit switch)")
    a.controlword(0x0F)
    wait_bits(a, 0x0400, "bit 4 fell: the drive stops, 0 0 1 interrupted")
    st = d.status()
    check(st["homing_reason"] == "interrupted" and abs(st["velocity"]) < 0.05 and st["machine_position"] > -0.5,
          "interrupted before the switch, standing: %s" % st)

    # Method 17 to the end: the switch's edge is the home position (0).
    a.controlword(0x1F)
    wait_bits(a, 0x0000, "method 17 again: in progress")
    wait_bits(a, 0x1400, "method 17: homing completed")
    st = d.status()
    # After the edge (machine -0.5) the drive brakes from 0.1 rad/s with
    # 20 rad/s^2: 0.25 mrad, and a few of the velocity loop's.
    check(abs(st["machine_position"] + 0.5) < 0.01, "it stands at the switch's edge: %s" % st["machine_position"])
    check(abs(a.actual()["position"]) < 0.01 * K, "the edge got the home offset 0: %d" % a.actual()["position"])
    # The edge is the first drive cycle off the switch: within one cycle's
    # travel at 6099h:2 (0.1 mrad) of -0.5.
    check(abs(st["position"] - (st["machine_position"] + 0.5)) < 2e-4,
          "drive position = machine position - the edge's: %s" % (st["position"] - st["machine_position"]))

    # Method 18 without a positive limit switch: a homing error at standstill.
    a.controlword(0x0F)
    wait_bits(a, 0x0400, "bit 4 low: not started")
    a.write(sim.HR_HOMING_METHOD, [18])
    a.controlword(0x1F)
    wait_bits(a, 0x2400, "method 18 without its switch: 1 0 1, homing error at standstill")
    check("positive" in d.status()["homing_reason"], "the reason: %s" % d.status()["homing_reason"])
    a.controlword(0x0F)
    wait_bits(a, 0x0400, "bit 4 low: the error is cleared, 0 0 1")
    # An unsupported method is an error too.
    a.write(sim.HR_HOMING_METHOD, [99])
    a.controlword(0x1F)
    wait_bits(a, 0x2400, "method 99 (not supported): homing error")
    a.controlword(0x0F)
    a.close()
    d.stop()


if __name__ == "__main__":
    main()
