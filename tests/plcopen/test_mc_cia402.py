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
- a move back to 0 rad ends Done at 0.

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
    drive = SimDrive("--axis", "1")
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

    hmi.write_coil(0, False, slave=1)
    wait("MC_Power off: Disabled", lambda: state() == DISABLED)
    hmi.close()
    server.stop()
    drive.stop()


if __name__ == "__main__":
    main()
