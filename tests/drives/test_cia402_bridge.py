"""CIA402_DRIVE in a real `syncplc run` against the simulated CiA 402 drive.
Until the Modbus TCP client driver carries the drive's objects, this script
is the bus: a thread copies the block's controlword, mode and targets from
the PLC's Modbus server (bridge.yaml) to the drive's holding registers, and
the drive's statusword, display, actual values and error code back, about
every 2 ms. Checked: the block walks the drive to Operation enabled, a CSP
stroke of 2 rad is followed, a drive fault reaches the block (fault, its
error code, an event in the PLC's event log), a reset edge re-enables.

    /usr/bin/python3 tests/drives/test_cia402_bridge.py build/syncplc
"""

import os
import struct
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "peers"))

import peerlib  # noqa: E402  (syncplc run on a free port, its own state directory)
from drivelib import SimDrive, check, client, sim  # noqa: E402

CPR = (1 << 20) / (2 * 3.141592653589793)


class Bridge(threading.Thread):
    """The bus between the PLC and the drive: one exchange after another."""

    def __init__(self, plc_port, drive_port):
        super().__init__(daemon=True)
        self.plc = client(plc_port)
        self.drive = client(drive_port)
        self.stop_flag = threading.Event()
        self.exchanges = 0
        self.error = None

    def run(self):
        try:
            while not self.stop_flag.is_set():
                out = self.plc.read_holding_registers(100, 6, slave=1).registers  # cw, mode, 607Ah, 60B1h
                self.drive.write_registers(sim.HR_CONTROLWORD, [out[0], out[1], out[2], out[3], 0, 0, out[4], out[5]],
                                           slave=1)
                ir = self.drive.read_input_registers(0, 8, slave=1).registers
                # 6041h, 6061h, 6064h, 606Ch, 603Fh into the PLC's holding registers 0..6
                self.plc.write_registers(0, ir[0:6] + [ir[sim.IR_ERROR_CODE]], slave=1)
                self.exchanges += 1
                time.sleep(0.001)
        except Exception as e:  # reported by the main thread
            self.error = e

    def stop(self):
        self.stop_flag.set()
        self.join(timeout=5)
        self.plc.close()
        self.drive.close()


def main():
    binary = peerlib.syncplc_binary()
    server = peerlib.Server(binary, os.path.join(HERE, "bridge.yaml"))
    drive = SimDrive("--axis", "1")
    bridge = Bridge(server.port, drive.port)
    bridge.start()
    hmi = client(server.port)

    def plc(address, count=1):
        return hmi.read_holding_registers(address, count, slave=1).registers

    def flags():
        return hmi.read_discrete_inputs(0, 2, slave=1).bits[:2]  # ready, fault

    def wait(what, pred, timeout=5.0):
        end = time.monotonic() + timeout
        while not pred():
            if bridge.error:
                raise bridge.error
            if time.monotonic() > end:
                raise AssertionError("timed out waiting for " + what)
            time.sleep(0.005)
        check(True, what)

    wait("the block sees Switch on disabled (state 1)", lambda: plc(110)[0] == 1)
    hmi.write_coil(0, True, slave=1)
    wait("enable: the block walks the drive to Operation enabled", lambda: flags()[0])
    check(drive.status()["transitions"][-3:] == [2, 3, 4], "the drive made 2, 3, 4")
    # The stroke: 0 -> 2 rad in pi/4 s, from the scan after Operation enabled.
    worst = 0.0
    end = time.monotonic() + 10
    while lreal(plc(116, 4)) < 2.0 - 1e-9 and time.monotonic() < end:  # x_set: the stroke's end
        worst = max(worst, abs(lreal(plc(112, 4))))
    check(lreal(plc(116, 4)) > 2.0 - 1e-9, "the block's set point reached 2 rad")
    end = time.monotonic() + 5
    while abs(drive.status()["position"] - 2.0) >= 2e-3 and time.monotonic() < end:
        time.sleep(0.01)
    x = drive.status()["position"]
    check(abs(x - 2.0) < 2e-3, "CSP stroke: the drive is at 2 rad (%.5f)" % x)
    # The following error the block sees includes the bridge's delay: a few
    # ms at up to 4 rad/s on a quiet machine, but this Python bridge can lag
    # 100 ms and more when ctest runs it beside a build. Generous: it tells a
    # drive that follows from one that does not (the stroke is 2 rad).
    check(worst < 0.6, "largest following error the block saw: %.4f rad" % worst)

    drive.ok("fault 0x7300")
    wait("a drive fault reaches the block", lambda: flags() == [False, True])
    wait("fault_code 16#7300", lambda: plc(111)[0] == 0x7300)
    hmi.write_coil(1, True, slave=1)
    wait("a reset edge: back to Operation enabled", lambda: flags() == [True, False])
    check(plc(111)[0] == 0, "fault_code 0 after the reset")
    check(drive.status()["transitions"][-6:] == [13, 14, 15, 2, 3, 4], "the drive made 13, 14, 15, 2, 3, 4")
    check(bridge.exchanges > 100, "%d exchanges" % bridge.exchanges)
    hmi.close()
    bridge.stop()
    drive.stop()
    server.stop()
    events = subprocess.run([binary, "events", "--kind", "driver-fault"], capture_output=True, text=True,
                            timeout=60).stdout
    check("CIA402_DRIVE: drive fault" in events, "the fault is in the PLC's event log")
    info = subprocess.run([binary, "events", "--kind", "info"], capture_output=True, text=True, timeout=60).stdout
    check("CIA402_DRIVE: drive fault cleared" in info, "and its recovery")


def lreal(regs):
    """An LREAL from four registers, high word first (the server's default)."""
    return struct.unpack(">d", struct.pack(">HHHH", *regs))[0]


if __name__ == "__main__":
    main()
