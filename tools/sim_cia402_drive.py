#!/usr/bin/python3
"""A simulated CiA 402 servo drive on Modbus TCP, for tests and demos.

One drive: the CiA 402 power drive system state machine (CiA 402-2 /
IEC 61800-7-201, the PDS finite state automaton with transitions 0-16), the
modes cyclic synchronous position (8), velocity (9), torque (10), profile
velocity (3) and homing (6: methods 35/37, and 17/18 with the limit switches
of --negative-limit/--positive-limit), and the axis plant of syncplc's sim_table driver (paper 000
eq. (25), P(s) = k/(s(tau s + 1)), exact zero-order-hold steps, the same
tau, gain and saturation defaults), integrated at its own rate (1 kHz by
default) on a thread of its own. The Modbus side is Debian's python3-pymodbus
(3.0) server: nothing of syncplc's. Run it with Debian's interpreter:

    /usr/bin/python3 tools/sim_cia402_drive.py --port 0 --axis 1

It prints "sim_cia402_drive: listening on 127.0.0.1:PORT unit U" once it
serves, then reads commands on stdin, one per line, answering "ok ..." or
"error ..." on stdout; the same commands are taken on a TCP control socket
with --control-port, and SIGUSR1 drops the connections, SIGUSR2 toggles
silent (docs/drives.md has the register map and the commands):

    drop                 close every client connection now (the drive keeps running)
    silent on|off        accept connections and requests but answer nothing
    garbage MODE|off     answer every request with a malformed reply: bytes, tid,
                         unit, function, length, short, oversized, exception
    delay MS [COUNT]     the next COUNT (default 1) replies leave MS ms late (a
                         drive that stalls; a reply whose connection closed
                         meanwhile is dropped)
    fault CODE [persist] a drive fault: Fault reaction active, then Fault, error
                         code 603Fh = CODE; persist: a fault reset does not clear
                         it until "fault clear"
    fault clear          the persistent fault's cause is gone (a reset now works)
    status               one line of JSON: state, statusword, position, velocity, ...
    quit                 stop (as SIGTERM and SIGINT do)

When its master's requests stop for --comm-timeout (default 0.1 s) in
Operation enabled, the drive reacts as object 6007h (holding register 19,
--abort-connection at start, default 0) says: 0 nothing, 1 fault (603Fh =
8100h), 2 disable voltage, 3 quick stop.

The code is the package tools/sim_cia402/ (one module a job: registers,
plant, state_machine, drive, faults, commands, main); this script is its
command line and keeps the names the tests use (the register map, the
plant, the states) importable as `sim_cia402_drive`.
"""

import sys

from sim_cia402.drive import SUPPORTED_MODES, Drive  # noqa: F401  (the names the tests use)
from sim_cia402.faults import GARBAGE_MODES, Faults, FaultyHandler, malformed  # noqa: F401
from sim_cia402.main import main, parse_args, run_cycles  # noqa: F401
from sim_cia402.plant import PAPER_GAIN, PAPER_TAU, AxisPlant  # noqa: F401
from sim_cia402.registers import *  # noqa: F401,F403
from sim_cia402.state_machine import *  # noqa: F401,F403

if __name__ == "__main__":
    sys.exit(main())
