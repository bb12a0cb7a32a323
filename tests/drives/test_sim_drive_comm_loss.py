"""The simulated CiA 402 drive's reaction to a lost master (object 6007h,
abort connection option code): the axis runs in profile velocity, the
master's requests stop (its client closes: a killed PLC), and after
--comm-timeout the drive reacts as 6007h says, seen through `status` (the
command channel, not a Modbus request) and then by a new client:

  0  no reaction: still Operation enabled, still moving;
  1  fault: Fault reaction active on the quick stop ramp, then Fault with
     603Fh = 8100h; a fault reset by the new master clears it;
  2  disable voltage: Switch on disabled at once (transition 9), coasting;
  3  quick stop: Quick stop active (transition 11), stopped on the ramp,
     then Switch on disabled (605Ah = 2).

Requests that keep coming (every 20 ms, 25 times faster than the
timeout) never trigger it. 6007h is written by the master (holding
register 19), or set at start with --abort-connection. Each reaction is
awaited as a condition on the drive's `status` (a minute's guard only
against a hang), so a loaded machine makes the test slower, not wrong.

    /usr/bin/python3 tests/drives/test_sim_drive_comm_loss.py
"""

import time

from drivelib import REPLY_GUARD, Axis, SimDrive, check, decode, sim

TIMEOUT = 0.5  # s, --comm-timeout: a request every 20 ms stays far inside it however the machine is loaded
SPEED = 20000  # counts/s, about 0.12 rad/s


def moving_axis(option, via_register=True):
    """A drive in profile velocity at SPEED with 6007h = option; the master's client."""
    args = ["--comm-timeout", str(TIMEOUT)]
    if not via_register:
        args += ["--abort-connection", str(option)]
    d = SimDrive(*args)
    a = Axis(d.port)
    if via_register:
        a.write(sim.HR_ABORT_CONNECTION, [option & 0xFFFF])
    a.enable(3)
    a.target_velocity(SPEED)
    end = time.monotonic() + REPLY_GUARD
    while a.actual()["velocity"] < SPEED // 2:
        if time.monotonic() > end:
            raise AssertionError("the axis does not move")
        time.sleep(0.01)
    return d, a


def silent_state(d, reacted):
    """The drive's status once `reacted(status)` holds (its master silent)."""
    end = time.monotonic() + REPLY_GUARD
    while True:
        st = d.status()
        if reacted(st) or time.monotonic() > end:
            return st
        time.sleep(0.02)


def main():
    # Requests every 20 ms: alive, no reaction however long.
    d, a = moving_axis(1)
    for _ in range(25):
        a.actual()
        time.sleep(0.02)
    check(decode(a.actual()["statusword"]) == sim.OPERATION_ENABLED and d.status()["comm_losses"] == 0,
          "6007h = 1, requests every 20 ms: no reaction")
    a.close()  # the master dies
    st = silent_state(d, lambda st: st["comm_losses"] >= 1)
    check(st["state"] in (sim.STATE_NAMES[sim.FAULT_REACTION], sim.STATE_NAMES[sim.FAULT]) and
          st["error_code"] == sim.ERROR_COMMUNICATION and st["comm_losses"] == 1,
          "6007h = 1: the master silent: fault 8100h (%s)" % st["state"])
    b = Axis(d.port)
    b.wait_state(sim.FAULT)
    check(b.actual()["error_code"] == 0x8100, "6007h = 1: 603Fh = 8100h seen by the new master")
    b.controlword(0x80)
    b.wait_state(sim.SWITCH_ON_DISABLED)
    check(b.actual()["error_code"] == 0, "6007h = 1: a fault reset by the new master clears it")
    b.close()
    d.stop()

    d, a = moving_axis(2)
    a.close()
    st = silent_state(d, lambda st: st["comm_losses"] >= 1)
    check(st["state"] == sim.STATE_NAMES[sim.SWITCH_ON_DISABLED] and st["transitions"][-1] == 9 and st["u"] == 0.0,
          "6007h = 2: disable voltage, Switch on disabled by transition 9, the power stage off")
    d.stop()

    d, a = moving_axis(3, via_register=False)  # --abort-connection 3
    a.close()
    st = silent_state(d, lambda st: 11 in st["transitions"])
    check(11 in st["transitions"], "6007h = 3 (--abort-connection): quick stop, transition 11")
    end = time.monotonic() + REPLY_GUARD
    while d.status()["state"] != sim.STATE_NAMES[sim.SWITCH_ON_DISABLED]:
        if time.monotonic() > end:
            raise AssertionError("6007h = 3: still %s" % d.status()["state"])
        time.sleep(0.02)
    st = d.status()
    check(abs(st["velocity"]) < 0.01 and st["transitions"][-1] == 12,
          "6007h = 3: stopped on the quick stop ramp, then Switch on disabled (605Ah = 2)")
    d.stop()

    d, a = moving_axis(0)
    a.close()
    time.sleep(5 * TIMEOUT)  # what must not happen: nothing to wait for
    st = d.status()
    check(st["state"] == sim.STATE_NAMES[sim.OPERATION_ENABLED] and st["velocity"] > 0 and st["comm_losses"] == 0,
          "6007h = 0: no reaction, the axis runs on")
    d.stop()
    print("test_sim_drive_comm_loss: OK")


if __name__ == "__main__":
    main()
