"""Homing mode (modes of operation 6) of the simulated drive, CiA 402-2 /
IEC 61800-7-201 homing mode. Methods:

  35, 37  the current position is the home position (no motion): at the
          start of bit 4 the position becomes the home offset 607Ch;
  17      negative limit switch: search it moving in - at 6099h:1, then move
          in + at 6099h:2 until it is left; that edge is the home position
          (it gets 607Ch), then stop with 609Ah;
  18      the same with the positive limit switch, searching in +.

Any other method, a switch the drive does not have (--negative-limit /
--positive-limit not given), a speed 0, or a search longer than
--homing-max-travel is a homing error. Controlword bit 4: 0 -> 1 starts,
1 -> 0 interrupts (the drive stops with 609Ah). Statusword bits 13, 12, 10
follow the homing mode table: 0 0 0 in progress, 0 0 1 interrupted or not
started, 0 1 1 completed, 1 0 0 error while moving, 1 0 1 error at
standstill (and 0 1 0 attained, still braking, is not used: the home
position is reported attained once the drive stands)."""

from .registers import (HR_HOME_OFFSET, HR_HOMING_ACCELERATION, HR_HOMING_METHOD, HR_HOMING_SPEED_SWITCH,
                        HR_HOMING_SPEED_ZERO, HR_PROFILE_ACCELERATION, s16, s32, u32)

IDLE, SEARCH, BACKOFF, BRAKE, ATTAINED, ERROR = range(6)
PHASE_NAMES = ["idle", "search", "backoff", "brake", "attained", "error"]
SW_TARGET_REACHED, SW_HOMING_ATTAINED, SW_HOMING_ERROR = 0x0400, 0x1000, 0x2000
CW_HOMING_START = 0x0010


class Homing:
    """The homing procedure of one drive; the drive calls cycle() in
    Operation enabled with display 6, and leave() otherwise."""

    def __init__(self, negative_limit, positive_limit, max_travel):
        self.negative_limit = negative_limit  # rad (machine coordinates), None: no switch
        self.positive_limit = positive_limit
        self.max_travel = max_travel
        self.phase = IDLE
        self.prev_start = False
        self.direction = 0
        self.start_position = 0.0
        self.reason = ""
        self.homings = 0  # homings attained, for `status`

    def leave(self):
        """Not in Operation enabled in homing mode: a homing in progress ends
        (the drive's other loops take over); attained and error are kept for
        the next look at the statusword only while bit 4 stays high."""
        if self.phase in (SEARCH, BACKOFF, BRAKE):
            self.phase = IDLE
        self.prev_start = False

    def switch_on(self, drive, direction):
        x = drive.machine_position()
        if direction < 0:
            return self.negative_limit is not None and x <= self.negative_limit
        return self.positive_limit is not None and x >= self.positive_limit

    def fail(self, reason):
        self.phase = ERROR
        self.reason = reason

    def begin(self, drive, r):
        method = s16(r[HR_HOMING_METHOD])
        self.reason = ""
        if method in (35, 37):
            drive.set_position(s32(r[HR_HOME_OFFSET], r[HR_HOME_OFFSET + 1]))
            self.phase = BRAKE  # attained once standing
            self.homings += 1
            return
        if method not in (17, 18):
            return self.fail("method %d not supported" % method)
        self.direction = -1 if method == 17 else 1
        if (self.negative_limit if method == 17 else self.positive_limit) is None:
            return self.fail("method %d: no %s limit switch" % (method, "negative" if method == 17 else "positive"))
        if u32(r[HR_HOMING_SPEED_SWITCH], r[HR_HOMING_SPEED_SWITCH + 1]) == 0 or \
                u32(r[HR_HOMING_SPEED_ZERO], r[HR_HOMING_SPEED_ZERO + 1]) == 0:
            return self.fail("homing speed 0")
        self.start_position = drive.machine_position()
        self.phase = BACKOFF if self.switch_on(drive, self.direction) else SEARCH

    def acceleration(self, r, k):
        acc = u32(r[HR_HOMING_ACCELERATION], r[HR_HOMING_ACCELERATION + 1])
        if acc == 0:
            acc = u32(r[HR_PROFILE_ACCELERATION], r[HR_PROFILE_ACCELERATION + 1])
        return acc / k

    def cycle(self, drive, r, controlword):
        """One cycle in homing mode: the velocity the drive ramps to (rad/s)."""
        k = drive.counts_per_rad
        start = bool(controlword & CW_HOMING_START)
        rising, falling = start and not self.prev_start, self.prev_start and not start
        self.prev_start = start
        if rising:
            self.begin(drive, r)
        elif falling:
            if self.phase in (SEARCH, BACKOFF, BRAKE):
                self.reason = "interrupted"
            self.phase = IDLE  # interrupted (stops), or a finished homing's bits cleared
        if self.phase == SEARCH:
            if self.switch_on(drive, self.direction):
                self.phase = BACKOFF
            elif abs(drive.machine_position() - self.start_position) > self.max_travel:
                self.fail("no switch within %g rad" % self.max_travel)
            else:
                return self.direction * u32(r[HR_HOMING_SPEED_SWITCH], r[HR_HOMING_SPEED_SWITCH + 1]) / k
        if self.phase == BACKOFF:
            if self.switch_on(drive, self.direction):
                return -self.direction * u32(r[HR_HOMING_SPEED_ZERO], r[HR_HOMING_SPEED_ZERO + 1]) / k
            # the switch's edge: the home position
            drive.set_position(s32(r[HR_HOME_OFFSET], r[HR_HOME_OFFSET + 1]))
            self.phase = BRAKE
            self.homings += 1
        if self.phase == BRAKE and drive.stopped():
            self.phase = ATTAINED
        return 0.0

    def statusword_bits(self, drive):
        bits = 0
        if self.phase == ATTAINED:
            bits |= SW_HOMING_ATTAINED
        elif self.phase == ERROR:
            bits |= SW_HOMING_ERROR
        if self.phase in (IDLE, ATTAINED, ERROR) and drive.stopped():
            bits |= SW_TARGET_REACHED
        return bits
