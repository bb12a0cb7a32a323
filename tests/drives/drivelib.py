"""What the simulated CiA 402 drive's tests share: start tools/sim_cia402_drive.py
on a free port, send it commands on stdin, talk to it with pymodbus or with
raw Modbus TCP frames, and stop it. Run with Debian's interpreter (the only
one that sees python3-pymodbus)."""

import atexit
import json
import os
import re
import socket
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TOOL = os.path.join(ROOT, "tools", "sim_cia402_drive.py")
sys.path.insert(0, os.path.join(ROOT, "tools"))
import sim_cia402_drive as sim  # noqa: E402  (the plant and the register map)

_running = []

# Only against a hang: how long a reply, a state or a value that must come
# may take, however loaded the machine.
REPLY_GUARD = 60.0


@atexit.register
def _kill_leftovers():
    for p in _running:
        if p.poll() is None:
            p.kill()
            p.wait()


class SimDrive:
    """One drive process; a safety --max-time ends it if the test cannot."""

    def __init__(self, *args, max_time=120):
        self.p = subprocess.Popen([sys.executable, TOOL, "--port", "0", "--max-time", str(max_time)] + list(args),
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1)
        _running.append(self.p)
        line = self.p.stdout.readline()
        m = re.search(r"listening on 127\.0\.0\.1:(\d+) unit (\d+)", line)
        if not m:
            raise AssertionError("the drive did not start: %r" % line)
        self.port = int(m.group(1))
        self.unit = int(m.group(2))
        self.control_port = None
        if "--control-port" in args:
            line = self.p.stdout.readline()
            m = re.search(r"control on 127\.0\.0\.1:(\d+)", line)
            if not m:
                raise AssertionError("no control port: %r" % line)
            self.control_port = int(m.group(1))

    def command(self, text):
        self.p.stdin.write(text + "\n")
        self.p.stdin.flush()
        answer = self.p.stdout.readline().strip()
        return answer

    def ok(self, text):
        answer = self.command(text)
        assert answer == "ok " + text, "%s -> %r" % (text, answer)

    def status(self):
        answer = self.command("status")
        assert answer.startswith("status "), answer
        return json.loads(answer[len("status "):])

    def stop(self):
        if self.p.poll() is None:
            self.p.send_signal(15)
            out, _ = self.p.communicate(timeout=10)
            assert "stopped after" in out, out
        return self.p.returncode


def client(port, timeout=2.0):
    from pymodbus.client import ModbusTcpClient
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=timeout, retries=0, retry_on_empty=False)
    assert c.connect(), "cannot connect to 127.0.0.1:%d" % port
    return c


def s32(regs, i):
    return sim.s32(regs[i], regs[i + 1])


class Axis:
    """A pymodbus client's view of the drive: the objects by name."""

    def __init__(self, port, unit=1):
        self.c = client(port)
        self.unit = unit

    def close(self):
        self.c.close()

    def actual(self):
        r = self.c.read_input_registers(0, sim.IR_COUNT, slave=self.unit)
        assert not r.isError(), r
        g = r.registers
        return {"statusword": g[sim.IR_STATUSWORD], "mode": sim.s16(g[sim.IR_MODES_DISPLAY]),
                "position": s32(g, sim.IR_POSITION_ACTUAL), "velocity": s32(g, sim.IR_VELOCITY_ACTUAL),
                "torque": sim.s16(g[sim.IR_TORQUE_ACTUAL]), "error_code": g[sim.IR_ERROR_CODE],
                "following_error": s32(g, sim.IR_FOLLOWING_ERROR), "cycles": sim.u32(g[10], g[11])}

    def write(self, address, values):
        r = self.c.write_registers(address, values, slave=self.unit)
        assert not r.isError(), r

    def controlword(self, v):
        self.write(sim.HR_CONTROLWORD, [v])

    def mode(self, m):
        self.write(sim.HR_MODES, [m & 0xFFFF])

    def target_position(self, counts):
        self.write(sim.HR_TARGET_POSITION, sim.words32(counts))

    def target_velocity(self, counts):
        self.write(sim.HR_TARGET_VELOCITY, sim.words32(counts))

    def wait_state(self, state, timeout=REPLY_GUARD):
        """Polls the statusword until it codes `state` (sim.* state)."""
        end = time.monotonic() + timeout
        while True:
            sw = self.actual()["statusword"]
            if decode(sw) == state:
                return sw
            if time.monotonic() > end:
                raise AssertionError("statusword 16#%04X (%s), waited for %s"
                                     % (sw, sim.STATE_NAMES[decode(sw)] if decode(sw) >= 0 else "?",
                                        sim.STATE_NAMES[state]))
            time.sleep(0.005)

    def enable(self, mode):
        self.mode(mode)
        self.wait_state(sim.SWITCH_ON_DISABLED)
        for cw, st in ((0x06, sim.READY), (0x07, sim.SWITCHED_ON), (0x0F, sim.OPERATION_ENABLED)):
            self.controlword(cw)
            self.wait_state(st)


def decode(sw):
    """The state coding table (the same masks as fblocks/drives/cia402_math.cpp)."""
    for mask, value, state in ((0x4F, 0x00, sim.NOT_READY), (0x4F, 0x40, sim.SWITCH_ON_DISABLED),
                               (0x6F, 0x21, sim.READY), (0x6F, 0x23, sim.SWITCHED_ON),
                               (0x6F, 0x27, sim.OPERATION_ENABLED), (0x6F, 0x07, sim.QUICK_STOP),
                               (0x4F, 0x0F, sim.FAULT_REACTION), (0x4F, 0x08, sim.FAULT)):
        if sw & mask == value:
            return state
    return -1


def raw_request(port, pdu, unit=1, tid=0x1234, timeout=1.0, reply=True):
    """Sends one Modbus TCP request on a fresh socket; returns the bytes
    received until the socket is quiet for `timeout` (b"" when nothing).
    With `reply` (a reply must come) the first byte is awaited up to
    REPLY_GUARD, however long a loaded machine takes, and only then the
    quiet `timeout` ends it; without, `timeout` is how long nothing must come."""
    with socket.create_connection(("127.0.0.1", port), timeout=REPLY_GUARD) as s:
        s.settimeout(REPLY_GUARD if reply else timeout)
        s.sendall(struct.pack(">HHHB", tid, 0, len(pdu) + 1, unit) + pdu)
        data = b""
        while True:
            try:
                chunk = s.recv(4096)
                s.settimeout(timeout)
            except socket.timeout:
                return data
            if not chunk:
                return data
            data += chunk


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print("ok  " + what)
