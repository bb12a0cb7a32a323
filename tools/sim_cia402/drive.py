"""One simulated drive: its objects in registers, the PDS state machine
(state_machine.py), the modes cyclic synchronous position (8), velocity (9),
torque (10), profile velocity (3) and homing (6, homing.py), and the axis
plant (plant.py), one cycle() per drive period."""

import math

from .homing import PHASE_NAMES, Homing
from .plant import AxisPlant
from .registers import (ERROR_FOLLOWING, HR_ABORT_CONNECTION, HR_COUNT, HR_FOLLOWING_ERROR_TIMEOUT,
                        HR_FOLLOWING_ERROR_WINDOW, HR_MODES, HR_PROFILE_ACCELERATION, HR_PROFILE_DECELERATION,
                        HR_QUICK_STOP_DECELERATION, HR_QUICK_STOP_OPTION, HR_TARGET_POSITION, HR_TARGET_TORQUE,
                        HR_TARGET_VELOCITY, HR_VELOCITY_OFFSET, HR_CONTROLWORD, IR_COUNT, IR_CYCLE_COUNTER,
                        IR_ERROR_CODE, IR_FOLLOWING_ERROR, IR_MODES_DISPLAY, IR_POSITION_ACTUAL, IR_STATUSWORD,
                        IR_TORQUE_ACTUAL, IR_VELOCITY_ACTUAL, MIRROR, LockedBlock, s16, s32, u32, words32)
from .state_machine import (FAULT_REACTION, OPERATION_ENABLED, QUICK_STOP, STATE_BITS, STATE_NAMES, SWITCHED_ON,
                            PdsStateMachine)

SUPPORTED_MODES = (3, 6, 8, 9, 10)


class Drive(PdsStateMachine):
    """The drive: its objects in registers, the PDS FSA (state_machine.py),
    the mode loops and the plant, one cycle() per drive period."""

    def __init__(self, a):
        super().__init__(a.comm_timeout)
        self.a = a
        self.h = 1.0 / a.rate
        self.counts_per_rad = a.counts_per_rev / (2 * math.pi)
        self.plant = AxisPlant(a.tau, a.gain, self.h, a.position0)
        # Homing moves the drive's coordinates against the machine's: the
        # limit switches stand at machine positions (plant.position - origin).
        self.origin = 0.0
        self.homing = Homing(a.negative_limit, a.positive_limit, a.homing_max_travel)
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
        defaults[HR_ABORT_CONNECTION] = a.abort_connection & 0xFFFF
        self.hr.setValues(0, defaults)
        self.not_ready_cycles = max(1, int(round(a.startup / self.h)))
        self.mode_display = 0
        self.v_ref = 0.0           # velocity reference of the ramps (rad/s)
        self.integral = 0.0        # velocity loop integral part (PWM)
        self.u = 0.0
        self.limited = False
        self.fe_since = None
        # The target-step check (status: target, max_target_step): the
        # largest change of 607Ah between two cycles in Operation enabled
        # in CSP, counting the first such cycle against the actual
        # position: a master that sends a target from stale data shows here.
        self.prev_target = None
        self.max_target_step = 0

    # -- one drive cycle --
    def cycle(self):
        r = self.hr.getValues(0, HR_COUNT)
        cw = r[HR_CONTROLWORD]
        mode = s16(r[HR_MODES])
        if mode in SUPPORTED_MODES:
            self.mode_display = mode  # an unsupported mode is refused: the display keeps the last one
        self.fsa(cw, r)
        if self.state != OPERATION_ENABLED or self.mode_display != 6:
            self.homing.leave()
        self.watch_target(r)
        self.control(r)
        self.plant.step(self.u)
        self.cycles += 1
        self.publish(r)

    def watch_target(self, r):
        if self.state == OPERATION_ENABLED and self.mode_display == 8:
            xt = s32(r[HR_TARGET_POSITION], r[HR_TARGET_POSITION + 1])
            ref = self.prev_target
            if ref is None:
                ref = math.floor(self.plant.position * self.counts_per_rad)
            self.max_target_step = max(self.max_target_step, abs(xt - ref))
            self.prev_target = xt
        else:
            self.prev_target = None

    def machine_position(self):
        return self.plant.position - self.origin

    def set_position(self, counts):
        """Homing: the position here becomes `counts` (the home offset)."""
        delta = counts / self.counts_per_rad - self.plant.position
        self.plant.position += delta
        self.origin += delta

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
            elif m == 6:
                acc = self.homing.acceleration(r, k)
                self.ramp(self.homing.cycle(self, r, r[HR_CONTROLWORD]), acc, acc)
                u = self.velocity_loop(self.v_ref, (self.v_ref - v_before) / self.h)
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
            elif self.mode_display == 6:
                sw |= self.homing.statusword_bits(self)
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
                "cycles": self.cycles, "transitions": [n for _, n in self.transitions],
                "comm_losses": self.comm_losses, "silent_for": self.liveness.silent_for(),
                "target": s32(*self.hr.getValues(HR_TARGET_POSITION, 2)),
                "max_target_step": self.max_target_step,
                "homing": PHASE_NAMES[self.homing.phase], "homing_reason": self.homing.reason,
                "homings": self.homing.homings, "machine_position": self.machine_position()}
