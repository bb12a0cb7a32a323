"""The command line, the drive's clock and the Modbus server (Debian's
python3-pymodbus 3.0): tools/sim_cia402_drive.py runs main()."""

import argparse
import asyncio
import logging
import signal
import sys
import threading
import time

from pymodbus.datastore import ModbusServerContext, ModbusSlaveContext
from pymodbus.server.async_io import ModbusTcpServer

from .commands import command, control_client, read_commands, say
from .drive import Drive
from .faults import Faults, FaultyHandler
from .plant import PAPER_GAIN, PAPER_TAU


def run_cycles(drive, stop, max_catch_up):
    """The drive's clock: cycle k runs at start + k h of wall-clock time;
    after a stall (a suspended process) at most max_catch_up cycles are run
    at once and the rest of the lost time is skipped."""
    h = drive.h
    start = time.monotonic()
    n = 0
    while not stop.is_set():
        due = int((time.monotonic() - start) / h) - n
        if due > max_catch_up:
            n += due - max_catch_up
            due = max_catch_up
        for _ in range(due):
            drive.cycle()
            n += 1
        delay = start + (n + 1) * h - time.monotonic()
        if delay > 0:
            time.sleep(delay)


def parse_args(argv):
    p = argparse.ArgumentParser(description="Simulated CiA 402 drive on Modbus TCP (pymodbus server).")
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, default=0, help="TCP port; 0 = a free port (printed)")
    p.add_argument("--control-port", type=int, default=None,
                   help="also take the stdin commands on this TCP port (0 = a free port, printed)")
    p.add_argument("--unit", type=int, default=1, help="Modbus unit id answered (others: no reply)")
    p.add_argument("--rate", type=float, default=1000.0, help="drive cycles per second (default 1000)")
    p.add_argument("--axis", type=int, default=1, choices=[1, 2, 3, 4],
                   help="take sim_table's default tau and gain of this axis (paper 000)")
    p.add_argument("--tau", type=float, help="mechanical time constant, s (default: the axis's)")
    p.add_argument("--gain", type=float, help="(rad/s)/PWM (default: the axis's)")
    p.add_argument("--saturation", type=float, default=1.0, help="|u| limit, PWM (sim_table's default 1)")
    p.add_argument("--position0", type=float, default=0.0, help="initial position, rad")
    p.add_argument("--counts-per-rev", type=int, default=1 << 20, help="position counts per revolution")
    p.add_argument("--torque-scale", type=float, default=1000.0,
                   help="target torque units (0.1 %% of rated) per PWM: u = 6071h / scale")
    p.add_argument("--kp", type=float, default=20.0, help="CSP position loop gain, PWM/rad")
    p.add_argument("--kd", type=float, default=0.5, help="CSP position loop damping, PWM.s/rad")
    p.add_argument("--kv", type=float, default=0.05, help="velocity loop gain, PWM.s/rad")
    p.add_argument("--ki", type=float, default=1.0, help="velocity loop integral gain, PWM/rad")
    p.add_argument("--acceleration", type=float, default=100.0,
                   help="default profile acceleration/deceleration 6083h/6084h, rad/s^2")
    p.add_argument("--quick-stop-deceleration", type=float, default=200.0, help="default 6085h, rad/s^2")
    p.add_argument("--startup", type=float, default=0.01, help="time in Not ready to switch on, s")
    p.add_argument("--abort-connection", type=int, default=0,
                   help="6007h at start, what the drive does when its master's requests stop for --comm-timeout "
                        "in Operation enabled: 0 nothing (default), 1 fault, 2 disable voltage, 3 quick stop "
                        "(the master may write it, holding register 19)")
    p.add_argument("--comm-timeout", type=float, default=0.1,
                   help="s without a request that count as a lost master for 6007h (default 0.1; 0 = never)")
    p.add_argument("--negative-limit", type=float, default=None,
                   help="machine position (rad) at and below which the negative limit switch is on (homing method 17)")
    p.add_argument("--positive-limit", type=float, default=None,
                   help="machine position (rad) at and above which the positive limit switch is on (homing method 18)")
    p.add_argument("--homing-max-travel", type=float, default=20.0,
                   help="a switch search longer than this (rad) is a homing error (default 20)")
    p.add_argument("--max-time", type=float, default=0.0, help="stop after this many seconds (0 = never)")
    p.add_argument("--verbose", action="store_true", help="pymodbus's log on stderr")
    a = p.parse_args(argv)
    if a.tau is None:
        a.tau = PAPER_TAU[a.axis - 1]
    if a.gain is None:
        a.gain = PAPER_GAIN[a.axis - 1]
    if not (a.rate > 0 and a.tau > 0 and a.gain > 0 and a.saturation > 0 and a.counts_per_rev > 0
            and a.torque_scale > 0):
        p.error("rate, tau, gain, saturation, counts-per-rev and torque-scale must be positive")
    if not -32768 <= a.abort_connection <= 32767 or a.comm_timeout < 0:
        p.error("abort-connection must be an INT16 (0..3 act) and comm-timeout not negative")
    if not 0 <= a.unit <= 255 or not 0 <= a.port <= 65535 or not 0 <= (a.control_port or 0) <= 65535:
        p.error("unit must be 0..255 and port 0..65535")
    return a


async def serve(a):
    drive = Drive(a)
    stop = threading.Event()
    loop = asyncio.get_running_loop()
    context = ModbusServerContext(slaves={a.unit: ModbusSlaveContext(hr=drive.hr, ir=drive.ir, zero_mode=True)},
                                  single=False)
    FaultyHandler.liveness = drive.liveness  # requests to this unit keep 6007h's reaction off
    FaultyHandler.unit = a.unit
    server = ModbusTcpServer(context, address=(a.host, a.port), handler=FaultyHandler,
                             allow_reuse_address=True, ignore_missing_slaves=True)
    serving = asyncio.create_task(server.serve_forever())
    await server.serving
    port = server.server.sockets[0].getsockname()[1]
    clock = threading.Thread(target=run_cycles, args=(drive, stop, 1000), name="drive", daemon=True)
    clock.start()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)
    # For shell scripts that hold no pipe to the drive: SIGUSR1 = drop,
    # SIGUSR2 = silent on/off.
    loop.add_signal_handler(signal.SIGUSR1, command, "drop", drive, loop, server, stop)
    loop.add_signal_handler(signal.SIGUSR2, lambda: setattr(Faults, "silent", not Faults.silent))
    say("sim_cia402_drive: listening on %s:%d unit %d (tau %g s, gain %g (rad/s)/PWM, %g Hz)"
        % (a.host, port, a.unit, a.tau, a.gain, a.rate))
    control = None
    if a.control_port is not None:
        control = await asyncio.start_server(lambda r, w: control_client(r, w, drive, loop, server, stop),
                                             a.host, a.control_port)
        say("sim_cia402_drive: control on %s:%d" % (a.host, control.sockets[0].getsockname()[1]))
    threading.Thread(target=read_commands, args=(drive, loop, server, stop), name="commands", daemon=True).start()
    deadline = time.monotonic() + a.max_time if a.max_time > 0 else None
    while not stop.is_set():
        await asyncio.sleep(0.05)
        if deadline and time.monotonic() > deadline:
            say("sim_cia402_drive: --max-time reached")
            stop.set()
    clock.join()
    if control:
        control.close()
    await server.shutdown()
    serving.cancel()
    say("sim_cia402_drive: stopped after %d cycles" % drive.cycles)


def main(argv=None):
    a = parse_args(sys.argv[1:] if argv is None else argv)
    if a.verbose:
        logging.basicConfig(level=logging.DEBUG)
    else:
        logging.disable(logging.CRITICAL)  # pymodbus logs every dropped client as an error
    asyncio.run(serve(a))
    return 0
