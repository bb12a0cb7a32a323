"""PLCopen blocks on a real link: `syncplc run` of cia402_axis.yaml, an
MC_AXIS on CIA402_DRIVE in CSP over the modbus_client driver, talking Modbus
TCP to the simulated CiA 402 drive on 127.0.0.1 (tools/sim_cia402_drive.py).
The test plays the program through the PLC's own Modbus server. Checked:

- MC_Power: the axis walks the drive to Operation enabled (2, 3, 4) and goes
  Disabled -> Standstill, MC_Power.Status TRUE;
- MC_MoveAbsolute to 2 rad: Busy, then Done with the set position exactly
  2 rad; the drive's own position ends within 2 mrad of it;
- a drive fault (the drive's `fault 0x7300`): ErrorStop, axis error 0x0301,
  the move's Error; the power stage is switched off;
- MC_Reset: the drive's fault is reset (13, 14, 15), the axis goes through
  Disabled and, MC_Power still enabled, back to Standstill (2, 3, 4);
- a move back to 0 rad ends Done at 0;
- MC_Home by the drive's homing mode (home_mode 3): method 37 makes the
  current position MC_Home's Position (1 rad), the axis takes it, homed; a
  move in the new coordinates; method 17 searches the drive's negative limit
  switch, whose edge becomes Position (0 rad);
- a homing error (method 18, the drive has no positive limit switch):
  ErrorStop 0x0307, MC_Home's Error; MC_Reset back to Standstill;
- MC_Home aborted by MC_Stop during the search: CommandAborted, the drive
  interrupts its homing and stands, MC_Stop Done, Standstill once released.

Waits are for conditions; times only guard against a hang.

    /usr/bin/python3 tests/plcopen/test_mc_cia402.py build/syncplc
"""

import os
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
TESTS = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(TESTS, "peers"))
sys.path.insert(0, os.path.join(TESTS, "drives"))

import peerlib  # noqa: E402  (syncplc run on a free port, its own state directory)
from drivelib import REPLY_GUARD, SimDrive, check, client  # noqa: E402

STANDSTILL, DISCRETE, ERRORSTOP, DISABLED = 1, 3, 7, 0


def lreal(regs):
    """An LREAL from four registers, high word first (the server's default)."""
    return struct.unpack(">d", struct.pack(">HHHH", *regs))[0]


def lreal_regs(v):
    return list(struct.unpack(">HHHH", struct.pack(">d", v)))


def main():
    binary = peerlib.syncplc_binary()
    drive = SimDrive("--axis", "1", "--negative-limit", "-0.5")
    server = peerlib.Server(binary, os.path.join(HERE, "cia402_axis.yaml"),
                            extra=("--set", "bus.devices.d.port=%d" % drive.port))
    hmi = client(server.port)

    def reg(address, count=1):
        return hmi.read_holding_registers(address, count, slave=1).registers

    def bits():
        return hmi.read_discrete_inputs(0, 5, slave=1).bits[:5]  # done, busy, error, reset done, powered

    def state():
        return reg(10)[0]

    def wait(what, pred, guard=REPLY_GUARD):
        end = time.monotonic() + guard
        while not pred():
            if time.monotonic() > end:
                raise AssertionError("timed out waiting for %s (axis state %d, error %04x)" % (what, state(), reg(11)[0]))
            time.sleep(0.005)
        check(True, what)

    wait("the axis starts Disabled", lambda: state() == DISABLED)
    hmi.write_coil(0, True, slave=1)
    wait("MC_Power: Standstill", lambda: state() == STANDSTILL)
    check(bits()[4], "MC_Power.Status: the power stage is on")
    check(drive.status()["transitions"][-3:] == [2, 3, 4], "the drive made 2, 3, 4")

    hmi.write_registers(0, lreal_regs(2.0), slave=1)
    hmi.write_coil(1, True, slave=1)
    wait("the move is busy", lambda: bits()[1] or bits()[0])
    wait("MC_MoveAbsolute: Done", lambda: bits()[0])
    check(lreal(reg(12, 4)) == 2.0, "the set position is exactly 2 rad")
    wait("the drive stands at 2 rad", lambda: abs(drive.status()["position"] - 2.0) < 2e-3)
    wait("MC_AXIS shows the actual position", lambda: abs(lreal(reg(16, 4)) - 2.0) < 2e-3)
    check(state() == STANDSTILL, "Standstill after the move")

    drive.ok("fault 0x7300")
    wait("a drive fault: ErrorStop", lambda: state() == ERRORSTOP)
    check(reg(11)[0] == 0x0301, "axis error 0x0301 (drive fault): %04x" % reg(11)[0])
    hmi.write_coil(1, False, slave=1)
    wait("the drive leaves Operation enabled", lambda: drive.status()["state"] != "Operation enabled")

    hmi.write_coil(2, True, slave=1)
    wait("MC_Reset: Done", lambda: bits()[3])
    wait("MC_Power still enabled: Standstill again", lambda: state() == STANDSTILL)
    t = drive.status()["transitions"]
    check(15 in t[-6:] and t[-3:] == [2, 3, 4], "the drive was reset (15) and enabled again (2, 3, 4): %s" % t[-8:])
    check(reg(11)[0] == 0, "no axis error after the reset")

    hmi.write_coil(2, False, slave=1)
    hmi.write_registers(0, lreal_regs(0.0), slave=1)
    hmi.write_coil(1, True, slave=1)
    wait("a move back to 0 rad: Done", lambda: bits()[0] and lreal(reg(12, 4)) == 0.0)
    wait("the drive stands at 0 rad", lambda: abs(drive.status()["position"]) < 2e-3)

    def home_bits():  # hm.Done, hm.Busy, hm.Error, hm.CommandAborted, st.Done, x.homed
        return hmi.read_discrete_inputs(5, 6, slave=1).bits[:6]

    def home(method, position):
        hmi.write_coil(3, False, slave=1)
        hmi.write_register(20, method, slave=1)
        hmi.write_registers(22, lreal_regs(position), slave=1)
        time.sleep(0.05)  # the tuning input and the home offset reach the drive before the edge
        hmi.write_coil(3, True, slave=1)

    def move(position):
        hmi.write_coil(1, False, slave=1)
        hmi.write_registers(0, lreal_regs(position), slave=1)
        time.sleep(0.05)  # a few scans with Execute low: the next TRUE is an edge
        hmi.write_coil(1, True, slave=1)
        wait("a move to %g rad: Done" % position, lambda: bits()[0] and lreal(reg(12, 4)) == position)

    # MC_Home, method 37: where the drive stands becomes 1 rad.
    check(not home_bits()[5], "not homed yet")
    home(37, 1.0)
    wait("MC_Home (drive homing, method 37): Done", lambda: home_bits()[0])
    st = drive.status()
    check(st["homings"] == 1 and abs(st["machine_position"]) < 2e-3, "the drive homed once, without moving: %s" % st)
    check(abs(st["position"] - 1.0) < 1e-5, "the drive's position is the home offset 1 rad: %r" % st["position"])
    check(abs(lreal(reg(16, 4)) - 1.0) < 1e-5, "MC_AXIS's actual position is the drive's: %r" % lreal(reg(16, 4)))
    check(abs(lreal(reg(12, 4)) - 1.0) < 1e-5, "and its set position: %r" % lreal(reg(12, 4)))
    check(home_bits()[5], "homed")
    wait("Standstill (a scan after Done)", lambda: state() == STANDSTILL)
    move(1.5)
    wait("the drive stands at 1.5 rad", lambda: abs(drive.status()["position"] - 1.5) < 2e-3)
    # A target computed in the old coordinates would step by 1 rad (166886
    # counts); a move at 2 rad/s steps 0.02 rad (3338 counts) a scan, a few
    # scans' worth at once when a loaded machine delays the writes.
    check(drive.status()["max_target_step"] < 0.25 * 166886,
          "no target jump: %d counts" % drive.status()["max_target_step"])

    # Method 17: the negative limit switch (machine position -0.5 rad) becomes 0 rad.
    home(17, 0.0)
    wait("MC_Home busy", lambda: home_bits()[1] or home_bits()[0])
    wait("MC_Home (method 17): Done", lambda: home_bits()[0], guard=REPLY_GUARD + 5)
    st = drive.status()
    check(st["homings"] == 2 and abs(st["machine_position"] + 0.5) < 0.01, "the drive stands at the switch: %s" % st)
    check(abs(st["position"]) < 0.01, "the switch's edge got 0 rad: %r" % st["position"])
    wait("MC_AXIS follows the drive", lambda: abs(lreal(reg(16, 4)) - drive.status()["position"]) < 1e-3)
    wait("Standstill, no error", lambda: state() == STANDSTILL and reg(11)[0] == 0)

    # A homing error: method 18, and the drive has no positive limit switch.
    home(18, 0.0)
    wait("a homing error: ErrorStop", lambda: state() == ERRORSTOP)
    check(reg(11)[0] == 0x0307, "axis error 0x0307 (the drive's homing error): %04x" % reg(11)[0])
    check(home_bits()[2], "MC_Home.Error")
    check(drive.status()["homing_reason"].startswith("method 18"), "the drive's reason: %s" % drive.status()["homing_reason"])
    hmi.write_coil(3, False, slave=1)
    hmi.write_coil(2, True, slave=1)
    wait("MC_Reset after the homing error: Standstill", lambda: state() == STANDSTILL)
    check(reg(11)[0] == 0, "no axis error after the reset")
    hmi.write_coil(2, False, slave=1)

    # MC_Home aborted by MC_Stop during the search.
    move(1.0)
    home(17, 0.0)
    wait("the drive searches its switch", lambda: drive.status()["homing"] == "search" and drive.status()["velocity"] < -0.5)
    hmi.write_coil(4, True, slave=1)
    wait("MC_Stop: Done", lambda: home_bits()[4])
    check(home_bits()[3], "MC_Home.CommandAborted")
    wait("the drive interrupted its homing and stands",
         lambda: drive.status()["homing_reason"] == "interrupted" and abs(drive.status()["velocity"]) < 0.05)
    check(drive.status()["homings"] == 2, "no homing completed")
    check(state() == 6, "MC_Stop holds the axis in Stopping")
    hmi.write_coil(4, False, slave=1)
    hmi.write_coil(3, False, slave=1)
    wait("MC_Stop released: Standstill", lambda: state() == STANDSTILL)
    wait("the drive stands where the axis says", lambda: abs(drive.status()["position"] - lreal(reg(12, 4))) < 2e-3)

    hmi.write_coil(0, False, slave=1)
    wait("MC_Power off: Disabled", lambda: state() == DISABLED)
    hmi.close()
    server.stop()
    drive.stop()


if __name__ == "__main__":
    main()
