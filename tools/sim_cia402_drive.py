#!/usr/bin/python3
"""A simulated CiA 402 servo drive on Modbus TCP, for tests and demos.

One drive: the CiA 402 power drive system state machine (CiA 402-2 /
IEC 61800-7-201, the PDS finite state automaton with transitions 0-16), the
modes cyclic synchronous position (8), velocity (9), torque (10) and profile
velocity (3), and the axis plant of syncplc's sim_table driver (paper 000
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
    fault CODE [persist] a drive fault: Fault reaction active, then Fault, error
                         code 603Fh = CODE; persist: a fault reset does not clear
                         it until "fault clear"
    fault clear          the persistent fault's cause is gone (a reset now works)
    status               one line of JSON: state, statusword, position, velocity, ...
    quit                 stop (as SIGTERM and SIGINT do)
"""

import argparse
import asyncio
import json
import logging
import math
import os
import random
import signal
import struct
import sys
import threading
import time

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.server.async_io import ModbusConnectedRequestHandler, ModbusTcpServer

# ---- the register map (docs/drives.md) ---------------------------------------
# Holding registers (FC 3, 6, 16, 23): what the master writes. 32-bit values
# take two registers, high word first (as syncplc's own server by default).
HR_CONTROLWORD = 0          # 6040h UINT16
HR_MODES = 1                # 6060h INT8 (sign-extended to 16 bits)
HR_TARGET_POSITION = 2      # 607Ah INT32, counts
HR_TARGET_VELOCITY = 4      # 60FFh INT32, counts/s
HR_VELOCITY_OFFSET = 6      # 60B1h INT32, counts/s (CSP feed-forward)
HR_TARGET_TORQUE = 8        # 6071h INT16, 0.1 % of rated torque
HR_QUICK_STOP_OPTION = 9    # 605Ah INT16
HR_PROFILE_ACCELERATION = 10  # 6083h UINT32, counts/s^2
HR_PROFILE_DECELERATION = 12  # 6084h UINT32, counts/s^2
HR_QUICK_STOP_DECELERATION = 14  # 6085h UINT32, counts/s^2
HR_FOLLOWING_ERROR_WINDOW = 16   # 6065h UINT32, counts; FFFFFFFFh = off
HR_FOLLOWING_ERROR_TIMEOUT = 18  # 6066h UINT16, ms
HR_COUNT = 19
# Input registers (FC 4): what the drive reports; also mirrored read-only at
# holding register MIRROR + i, so one FC 23 can write the commands and read
# the actual values in one round trip.
IR_STATUSWORD = 0           # 6041h UINT16
IR_MODES_DISPLAY = 1        # 6061h INT8 (sign-extended)
IR_POSITION_ACTUAL = 2      # 6064h INT32, counts
IR_VELOCITY_ACTUAL = 4      # 606Ch INT32, counts/s
IR_TORQUE_ACTUAL = 6        # 6077h INT16, 0.1 % of rated torque
IR_ERROR_CODE = 7           # 603Fh UINT16
IR_FOLLOWING_ERROR = 8      # 60F4h INT32, counts
IR_CYCLE_COUNTER = 10       # UINT32, drive cycles since start (vendor-specific)
IR_COUNT = 12
MIRROR = 100

# The sim_table defaults, paper 000 section 5.1 (runtime/io/sim_table.cpp):
# axes 1-3 measured, axis 4 = axis 2's model.
PAPER_TAU = [0.055, 0.056, 0.040, 0.056]
PAPER_GAIN = [35.6206, 36.3872, 52.2836, 36.3872]

# PDS FSA states (values as CIA402_DRIVE's `state` output).
NOT_READY, SWITCH_ON_DISABLED, READY, SWITCHED_ON, OPERATION_ENABLED, QUICK_STOP, FAULT_REACTION, FAULT = range(8)
STATE_NAMES = ["Not ready to switch on", "Switch on disabled", "Ready to switch on", "Switched on",
               "Operation enabled", "Quick stop active", "Fault reaction active", "Fault"]
# The state coding of 6041h bits 0-3, 5, 6 (bit 5, quick stop, is low active).
STATE_BITS = [0x00, 0x40, 0x21, 0x23, 0x27, 0x07, 0x0F, 0x08]

ERROR_FOLLOWING = 0x8611    # "following error" (CiA 402 error code table)
SUPPORTED_MODES = (3, 8, 9, 10)


def s16(v):
    return v - 0x10000 if v & 0x8000 else v


def s32(hi, lo):
    v = (hi << 16) | lo
    return v - 0x100000000 if v & 0x80000000 else v


def u32(hi, lo):
    return (hi << 16) | lo


def words32(v):
    v &= 0xFFFFFFFF
    return [v >> 16, v & 0xFFFF]


class AxisPlant:
    """sim_table's axis (runtime/io/axis_plant.*): theta' = omega,
    omega' = (k u - omega)/tau, u held over a step of h seconds, stepped
    exactly: with a = exp(-h/tau),
      theta+ = theta + tau (1 - a) omega + k (h - tau (1 - a)) u
      omega+ = a omega + k (1 - a) u
    (the closed form of exp([A B; 0 0] h) that axis_plant.cpp computes with
    Eigen's matrix exponential)."""

    def __init__(self, tau, gain, h, position=0.0):
        e = -math.expm1(-h / tau)  # 1 - a, without cancellation
        self.phi12 = tau * e
        self.phi22 = 1.0 - e
        self.g1 = gain * (h - tau * e)
        self.g2 = gain * e
        self.position = position
        self.velocity = 0.0

    def step(self, u):
        x, w = self.position, self.velocity
        self.position = x + self.phi12 * w + self.g1 * u
        self.velocity = self.phi22 * w + self.g2 * u


class LockedBlock(ModbusSequentialDataBlock):
    """A register block read and written whole under a lock: the drive thread
    and the server's requests never see half of a 32-bit value."""

    def __init__(self, address, values):
        super().__init__(address, values)
        self.lock = threading.Lock()

    def getValues(self, address, count=1):  # noqa: N802 (pymodbus's name)
        with self.lock:
            return super().getValues(address, count)

    def setValues(self, address, values):  # noqa: N802
        with self.lock:
            super().setValues(address, values)


class Drive:
    """The drive: its objects in registers, the PDS FSA, the mode loops and
    the plant, one cycle() per drive period."""

    def __init__(self, a):
        self.a = a
        self.h = 1.0 / a.rate
        self.counts_per_rad = a.counts_per_rev / (2 * math.pi)
        self.plant = AxisPlant(a.tau, a.gain, self.h, a.position0)
        self.hr = LockedBlock(0, [0] * (MIRROR + IR_COUNT))
        self.ir = LockedBlock(0, [0] * IR_COUNT)
        defaults = [0] * HR_COUNT
        defaults[HR_QUICK_STOP_OPTION] = 2  # slow down on the quick stop ramp, then Switch on disabled
        acc = int(a.acceleration * self.counts_per_rad)
        defaults[HR_PROFILE_ACCELERATION:HR_PROFILE_ACCELERATION + 2] = words32(acc)
        defaults[HR_PROFILE_DECELERATION:HR_PROFILE_DECELERATION + 2] = words32(acc)
        defaults[HR_QUICK_STOP_DECELERATION:HR_QUICK_STOP_DECELERATION + 2] = words32(
            int(a.quick_stop_deceleration * self.counts_per_rad))
        defaults[HR_FOLLOWING_ERROR_WINDOW:HR_FOLLOWING_ERROR_WINDOW + 2] = [0xFFFF, 0xFFFF]
        self.hr.setValues(0, defaults)
        self.state = NOT_READY
        self.not_ready_cycles = max(1, int(round(a.startup / self.h)))
        self.mode_display = 0
        self.prev_cw = 0
        self.error_code = 0
        self.fault_pending = None  # error code of an injected fault not yet acted on
        self.persistent = False
        self.v_ref = 0.0           # velocity reference of the ramps (rad/s)
        self.integral = 0.0        # velocity loop integral part (PWM)
        self.u = 0.0
        self.limited = False
        self.fe_since = None
        self.cycles = 0
        self.transitions = []      # (cycle, number) of the FSA, for `status`
        self.ctl_lock = threading.Lock()

    # -- fault injection (from the command thread) --
    def inject_fault(self, code, persist):
        with self.ctl_lock:
            self.fault_pending = code
            self.persistent = persist

    def clear_persistent(self):
        with self.ctl_lock:
            self.persistent = False

    def go(self, state, n):
        self.state = state
        self.transitions.append((self.cycles, n))
        del self.transitions[:-32]

    # -- one drive cycle --
    def cycle(self):
        r = self.hr.getValues(0, HR_COUNT)
        cw = r[HR_CONTROLWORD]
        mode = s16(r[HR_MODES])
        if mode in SUPPORTED_MODES:
            self.mode_display = mode  # an unsupported mode is refused: the display keeps the last one
        self.fsa(cw, r)
        self.control(r)
        self.plant.step(self.u)
        self.cycles += 1
        self.publish(r)

    def fsa(self, cw, r):
        """One transition at most per cycle, from the command coding table
        (controlword bits 7, 3, 2, 1, 0)."""
        reset_edge = bool(cw & 0x80) and not self.prev_cw & 0x80
        self.prev_cw = cw
        with self.ctl_lock:
            pending, self.fault_pending = self.fault_pending, None
            persistent = self.persistent
        if pending is not None:
            self.error_code = pending
            if self.state not in (FAULT_REACTION, FAULT):
                self.go(FAULT_REACTION, 13)
                return
        disable_voltage = not cw & 0x02
        quick_stop = (cw & 0x06) == 0x02
        shutdown = (cw & 0x87) == 0x06
        switch_on = (cw & 0x8F) == 0x07
        enable_op = (cw & 0x8F) == 0x0F
        s = self.state
        if s == NOT_READY:
            self.not_ready_cycles -= 1
            if self.not_ready_cycles <= 0:
                self.go(SWITCH_ON_DISABLED, 1)
        elif s == SWITCH_ON_DISABLED:
            if shutdown:
                self.go(READY, 2)
        elif s == READY:
            if switch_on or enable_op:
                self.go(SWITCHED_ON, 3)
            elif disable_voltage or quick_stop:
                self.go(SWITCH_ON_DISABLED, 7)
        elif s == SWITCHED_ON:
            if enable_op:
                self.enter_operation()
                self.go(OPERATION_ENABLED, 4)
            elif shutdown:
                self.go(READY, 6)
            elif disable_voltage or quick_stop:
                self.go(SWITCH_ON_DISABLED, 10)
        elif s == OPERATION_ENABLED:
            if switch_on:
                self.go(SWITCHED_ON, 5)
            elif shutdown:
                self.go(READY, 8)
            elif disable_voltage:
                self.go(SWITCH_ON_DISABLED, 9)
            elif quick_stop:
                self.go(QUICK_STOP, 11)
        elif s == QUICK_STOP:
            option = s16(r[HR_QUICK_STOP_OPTION])
            if disable_voltage:
                self.go(SWITCH_ON_DISABLED, 12)
            elif option >= 5 and enable_op:
                self.enter_operation()
                self.go(OPERATION_ENABLED, 16)
            elif option <= 4 and self.stopped():
                self.go(SWITCH_ON_DISABLED, 12)
        elif s == FAULT_REACTION:
            if self.stopped():
                self.go(FAULT, 14)
        elif s == FAULT:
            if reset_edge and not persistent:
                self.error_code = 0
                self.go(SWITCH_ON_DISABLED, 15)

    def enter_operation(self):
        self.v_ref = self.plant.velocity
        self.integral = 0.0
        self.fe_since = None

    def stopped(self):
        return self.v_ref == 0.0 and abs(self.plant.velocity) < 0.01

    def ramp(self, target, up, down):
        """Moves v_ref towards target by at most acc*h (up) or dec*h (down)."""
        v = self.v_ref
        rate = up if abs(target) > abs(v) and target * v >= 0 else down
        step = rate * self.h
        self.v_ref = target if abs(target - v) <= step else v + math.copysign(step, target - v)

    def velocity_loop(self, v_ref, acc_ref):
        """u = (v_r + tau a_r)/k + K_v e + I: the plant's inverse as the
        feed-forward (speed and acceleration), a PI on the speed error."""
        a = self.a
        e = v_ref - self.plant.velocity
        v = (v_ref + a.tau * acc_ref) / a.gain + a.kv * e + self.integral
        u = max(-a.saturation, min(a.saturation, v))
        if u == v or (v > u) != (e > 0):  # conditional integration (anti-windup)
            self.integral += a.ki * self.h * e
        return u

    def control(self, r):
        a = self.a
        k = self.counts_per_rad
        s = self.state
        u = 0.0  # power stage off: the motor coasts
        v_before = self.v_ref
        if s in (QUICK_STOP, FAULT_REACTION):
            dec = u32(r[HR_QUICK_STOP_DECELERATION], r[HR_QUICK_STOP_DECELERATION + 1]) / k
            self.ramp(0.0, dec, dec)
            u = self.velocity_loop(self.v_ref, (self.v_ref - v_before) / self.h)
        elif s == OPERATION_ENABLED:
            m = self.mode_display
            if m == 8:
                xt = s32(r[HR_TARGET_POSITION], r[HR_TARGET_POSITION + 1]) / k
                vff = s32(r[HR_VELOCITY_OFFSET], r[HR_VELOCITY_OFFSET + 1]) / k
                u = vff / a.gain + a.kp * (xt - self.plant.position) + a.kd * (vff - self.plant.velocity)
                self.v_ref = self.plant.velocity
                window = u32(r[HR_FOLLOWING_ERROR_WINDOW], r[HR_FOLLOWING_ERROR_WINDOW + 1])
                fe = abs(xt - self.plant.position) * k
                if window != 0xFFFFFFFF and fe > window:
                    if self.fe_since is None:
                        self.fe_since = self.cycles
                    if (self.cycles - self.fe_since) * self.h * 1000 >= r[HR_FOLLOWING_ERROR_TIMEOUT]:
                        self.error_code = ERROR_FOLLOWING
                        self.go(FAULT_REACTION, 13)
                else:
                    self.fe_since = None
            elif m in (3, 9):
                vt = s32(r[HR_TARGET_VELOCITY], r[HR_TARGET_VELOCITY + 1]) / k
                if m == 3:  # profile velocity: ramp with 6083h / 6084h
                    acc = u32(r[HR_PROFILE_ACCELERATION], r[HR_PROFILE_ACCELERATION + 1]) / k
                    dec = u32(r[HR_PROFILE_DECELERATION], r[HR_PROFILE_DECELERATION + 1]) / k
                    self.ramp(vt, acc, dec)
                    u = self.velocity_loop(self.v_ref, (self.v_ref - v_before) / self.h)
                else:
                    self.v_ref = vt  # CSV: the master's target is the reference, no acceleration feed-forward
                    u = self.velocity_loop(self.v_ref, 0.0)
            elif m == 10:
                u = s16(r[HR_TARGET_TORQUE]) / a.torque_scale
                self.v_ref = self.plant.velocity  # a quick stop ramps down from here
        self.u = max(-a.saturation, min(a.saturation, u))
        self.limited = u != self.u

    def statusword(self, r):
        s = self.state
        sw = STATE_BITS[s] | 0x0200  # bit 9 remote
        if s in (SWITCHED_ON, OPERATION_ENABLED, QUICK_STOP, FAULT_REACTION):
            sw |= 0x0010  # voltage enabled
        if s == OPERATION_ENABLED:
            k = self.counts_per_rad
            if self.limited:
                sw |= 0x0800  # internal limit active
            if self.mode_display == 8:
                sw |= 0x1000  # drive follows the command value
                if self.fe_since is not None:
                    sw |= 0x2000  # following error
                xt = s32(r[HR_TARGET_POSITION], r[HR_TARGET_POSITION + 1]) / k
                if abs(xt - self.plant.position) * k < 100:
                    sw |= 0x0400  # target reached
            elif self.mode_display in (3, 9):
                vt = s32(r[HR_TARGET_VELOCITY], r[HR_TARGET_VELOCITY + 1]) / k
                if abs(vt - self.plant.velocity) < 0.01 * max(1.0, abs(vt)):
                    sw |= 0x0400
                if abs(self.plant.velocity) < 0.01:
                    sw |= 0x1000  # PV: speed = 0
        elif s == QUICK_STOP and self.stopped():
            sw |= 0x0400
        return sw

    def publish(self, r):
        k = self.counts_per_rad
        p = self.plant
        position = math.floor(p.position * k)  # the position counter truncates, as sim_table's encoder
        if self.state == OPERATION_ENABLED and self.mode_display == 8:
            fe = s32(r[HR_TARGET_POSITION], r[HR_TARGET_POSITION + 1]) - position
        else:
            fe = 0
        regs = [0] * IR_COUNT
        regs[IR_STATUSWORD] = self.statusword(r)
        regs[IR_MODES_DISPLAY] = self.mode_display & 0xFFFF
        regs[IR_POSITION_ACTUAL:IR_POSITION_ACTUAL + 2] = words32(position)  # wraps as a drive's counter
        regs[IR_VELOCITY_ACTUAL:IR_VELOCITY_ACTUAL + 2] = words32(int(round(p.velocity * k)))
        regs[IR_TORQUE_ACTUAL] = int(round(self.u * self.a.torque_scale)) & 0xFFFF
        regs[IR_ERROR_CODE] = self.error_code
        regs[IR_FOLLOWING_ERROR:IR_FOLLOWING_ERROR + 2] = words32(max(-2**31, min(2**31 - 1, fe)))
        regs[IR_CYCLE_COUNTER:IR_CYCLE_COUNTER + 2] = words32(self.cycles)
        self.ir.setValues(0, regs)
        self.hr.setValues(MIRROR, regs)

    def status(self):
        r = self.ir.getValues(0, IR_COUNT)
        return {"state": STATE_NAMES[self.state], "statusword": r[IR_STATUSWORD],
                "mode_display": self.mode_display, "position": self.plant.position,
                "velocity": self.plant.velocity, "u": self.u, "error_code": self.error_code,
                "cycles": self.cycles, "transitions": [n for _, n in self.transitions]}


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


class Faults:
    """What the server does to its replies; set by the command thread."""
    silent = False
    garbage = None  # None or a mode


GARBAGE_MODES = ("bytes", "tid", "unit", "function", "length", "short", "oversized", "exception")


def malformed(frame, mode):
    """A reply that breaks the Modbus TCP rules in one way (MBAP header:
    transaction id, protocol 0, length, unit; then the PDU)."""
    tid, proto, length, unit = struct.unpack(">HHHB", frame[:7])
    pdu = frame[7:]
    fc = pdu[0]
    if mode == "bytes":
        return bytes(random.getrandbits(8) for _ in range(len(frame)))
    if mode == "tid":
        return struct.pack(">HHHB", (tid + 1) & 0xFFFF, proto, length, unit) + pdu
    if mode == "unit":
        return struct.pack(">HHHB", tid, proto, length, (unit + 1) & 0xFF) + pdu
    if mode == "function":
        other = 0x04 if fc == 0x03 else 0x03
        return struct.pack(">HHHB", tid, proto, length, unit) + bytes([other]) + pdu[1:]
    if mode == "length":  # the header claims 4 more bytes than follow
        return struct.pack(">HHHB", tid, proto, length + 4, unit) + pdu
    if mode == "short":   # the byte count says more registers than the reply holds
        if fc in (3, 4, 23) and len(pdu) > 3:
            body = bytes([fc, pdu[1] + 2]) + pdu[2:]
            return struct.pack(">HHHB", tid, proto, len(body) + 1, unit) + body
        return frame[:-1]
    if mode == "oversized":  # 300 registers: beyond the 125 a reply may carry (260-byte ADU)
        body = bytes([fc, 250]) + bytes(600)
        return struct.pack(">HHHB", tid, proto, len(body) + 1, unit) + body
    if mode == "exception":  # server device busy (06h) for every request
        return struct.pack(">HHHB", tid, proto, 3, unit) + bytes([fc | 0x80, 0x06])
    return frame


class FaultyHandler(ModbusConnectedRequestHandler):
    """pymodbus's connection handler with the injected reply faults."""

    def send(self, message, *addr, **kwargs):
        if Faults.silent:
            return
        mode = Faults.garbage
        if mode is None or kwargs.get("skip_encoding") or not message.should_respond:
            super().send(message, *addr, **kwargs)
            return
        self._send_(malformed(self.framer.buildPacket(message), mode))


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
    if not 0 <= a.unit <= 255 or not 0 <= a.port <= 65535 or not 0 <= (a.control_port or 0) <= 65535:
        p.error("unit must be 0..255 and port 0..65535")
    return a


def say(text):
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def command(line, drive, loop, server, stop):
    """Runs one fault-injection command; returns the answer line ("" for
    an empty line). Called from the stdin thread and the control socket."""
    words = line.split()
    if not words:
        return ""
    cmd, args = words[0], words[1:]
    try:
        if cmd == "drop":
            def drop():
                for handler in list(server.active_connections.values()):
                    handler.transport.abort()
            loop.call_soon_threadsafe(drop)
        elif cmd == "silent" and args in (["on"], ["off"]):
            Faults.silent = args[0] == "on"
        elif cmd == "garbage" and len(args) == 1 and (args[0] in GARBAGE_MODES or args[0] == "off"):
            Faults.garbage = None if args[0] == "off" else args[0]
        elif cmd == "fault" and args == ["clear"]:
            drive.clear_persistent()
        elif cmd == "fault" and 1 <= len(args) <= 2 and (len(args) == 1 or args[1] == "persist"):
            code = int(args[0], 0)
            if not 0 < code <= 0xFFFF:
                raise ValueError("error code must be 1..0xFFFF")
            drive.inject_fault(code, len(args) == 2)
        elif cmd == "status":
            return "status " + json.dumps(drive.status())
        elif cmd == "quit":
            stop.set()
        else:
            return "error unknown command: " + line.strip()
        return "ok " + " ".join(words)
    except ValueError as e:
        return "error %s: %s" % (line.strip(), e)


def read_commands(drive, loop, server, stop):
    for line in sys.stdin:
        answer = command(line, drive, loop, server, stop)
        if answer:
            say(answer)
        if stop.is_set():
            break
    # stdin closed: keep running (a drive started without a terminal)


async def control_client(reader, writer, drive, loop, server, stop):
    """The control socket: the stdin commands, one per line, answered on the socket."""
    try:
        while not stop.is_set():
            line = await reader.readline()
            if not line:
                break
            answer = command(line.decode("utf-8", "replace"), drive, loop, server, stop)
            if answer:
                writer.write((answer + "\n").encode())
                await writer.drain()
    except (ConnectionError, asyncio.CancelledError):
        pass
    finally:
        writer.close()


async def serve(a):
    drive = Drive(a)
    stop = threading.Event()
    loop = asyncio.get_running_loop()
    context = ModbusServerContext(slaves={a.unit: ModbusSlaveContext(hr=drive.hr, ir=drive.ir, zero_mode=True)},
                                  single=False)
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


if __name__ == "__main__":
    sys.exit(main())
