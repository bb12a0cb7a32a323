"""The CiA 402 power drive system state machine (CiA 402-2 / IEC
61800-7-201, the PDS finite state automaton with transitions 0-16), and the
drive's reaction when its master's requests stop (object 6007h, abort
connection option code)."""

import threading
import time

from .registers import ERROR_COMMUNICATION, HR_ABORT_CONNECTION, HR_QUICK_STOP_OPTION, s16

# PDS FSA states (values as CIA402_DRIVE's `state` output).
NOT_READY, SWITCH_ON_DISABLED, READY, SWITCHED_ON, OPERATION_ENABLED, QUICK_STOP, FAULT_REACTION, FAULT = range(8)
STATE_NAMES = ["Not ready to switch on", "Switch on disabled", "Ready to switch on", "Switched on",
               "Operation enabled", "Quick stop active", "Fault reaction active", "Fault"]
# The state coding of 6041h bits 0-3, 5, 6 (bit 5, quick stop, is low active).
STATE_BITS = [0x00, 0x40, 0x21, 0x23, 0x27, 0x07, 0x0F, 0x08]

# 6007h abort connection option codes (CiA 402-2): what the drive does when
# the connection to its master is lost.
ABORT_NONE, ABORT_FAULT, ABORT_DISABLE_VOLTAGE, ABORT_QUICK_STOP = 0, 1, 2, 3


class Liveness:
    """When the master's last request arrived (the server's thread marks it,
    the drive's thread reads it)."""

    def __init__(self):
        self.last = time.monotonic()

    def seen(self):
        self.last = time.monotonic()

    def silent_for(self):
        return time.monotonic() - self.last


class PdsStateMachine:
    """The FSA part of a drive. The drive supplies stopped() and
    enter_operation() (its mode loops), and calls fsa() once a cycle."""

    def __init__(self, comm_timeout):
        self.state = NOT_READY
        self.prev_cw = 0
        self.error_code = 0
        self.fault_pending = None  # error code of an injected fault not yet acted on
        self.persistent = False
        self.cycles = 0
        self.transitions = []      # (cycle, number) of the FSA, for `status`
        self.ctl_lock = threading.Lock()
        self.liveness = Liveness()
        self.comm_timeout = comm_timeout  # s without a request before 6007h's reaction; 0 = never
        self.comm_losses = 0       # 6007h reactions taken

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

    def comm_lost(self, r):
        """6007h: in Operation enabled, no request for comm_timeout: the
        master is gone (killed, unplugged), and the drive must not run on
        with its last set-points. 1: a fault (603Fh = 8100h, Fault reaction
        active with the quick stop ramp, then Fault); 2: disable voltage
        (transition 9, the motor coasts); 3: quick stop (transition 11, then
        605Ah). 0 (and manufacturer-specific values): no reaction. True when
        it reacted (once: the drive has left Operation enabled)."""
        if self.state != OPERATION_ENABLED or self.comm_timeout <= 0:
            return False
        option = s16(r[HR_ABORT_CONNECTION])
        if option not in (ABORT_FAULT, ABORT_DISABLE_VOLTAGE, ABORT_QUICK_STOP):
            return False
        if self.liveness.silent_for() < self.comm_timeout:
            return False
        self.comm_losses += 1
        if option == ABORT_FAULT:
            self.error_code = ERROR_COMMUNICATION
            self.go(FAULT_REACTION, 13)
        elif option == ABORT_DISABLE_VOLTAGE:
            self.go(SWITCH_ON_DISABLED, 9)
        else:
            self.go(QUICK_STOP, 11)
        return True

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
        if self.comm_lost(r):
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
