"""The simulated CiA 402 drive's state machine over Modbus TCP, through a
pymodbus client: every transition a master can command (2-12, 15, 16), the
automatic ones (0, 1, 12 after a quick stop, 13, 14), and the modes display.

    /usr/bin/python3 tests/drives/test_sim_drive_fsa.py
"""

import time

from drivelib import Axis, SimDrive, check, decode, sim


def transitions(drive):
    return drive.status()["transitions"]


def main():
    d = SimDrive()
    a = Axis(d.port)
    sw = a.wait_state(sim.SWITCH_ON_DISABLED)
    check(sw & 0x0200, "bit 9 (remote) set")
    check(transitions(d) == [1], "power on: Not ready to switch on -> Switch on disabled (1)")
    check(a.actual()["mode"] == 0, "modes display 0 before a mode is written")

    a.mode(8)
    time.sleep(0.02)
    check(a.actual()["mode"] == 8, "modes display follows 6060h = 8 (CSP)")
    a.mode(2)  # not supported: the display keeps the last mode
    time.sleep(0.02)
    check(a.actual()["mode"] == 8, "an unsupported mode (2) is not displayed")
    a.mode(8)

    steps = [  # (controlword, expected state, transition)
        (0x06, sim.READY, 2), (0x07, sim.SWITCHED_ON, 3), (0x0F, sim.OPERATION_ENABLED, 4),
        (0x07, sim.SWITCHED_ON, 5), (0x06, sim.READY, 6), (0x00, sim.SWITCH_ON_DISABLED, 7),
        (0x06, sim.READY, 2), (0x07, sim.SWITCHED_ON, 3), (0x0F, sim.OPERATION_ENABLED, 4),
        (0x06, sim.READY, 8), (0x07, sim.SWITCHED_ON, 3), (0x0F, sim.OPERATION_ENABLED, 4),
        (0x00, sim.SWITCH_ON_DISABLED, 9), (0x06, sim.READY, 2), (0x07, sim.SWITCHED_ON, 3),
        (0x02, sim.SWITCH_ON_DISABLED, 10), (0x06, sim.READY, 2), (0x02, sim.SWITCH_ON_DISABLED, 7),
    ]
    for cw, state, n in steps:
        a.controlword(cw)
        sw = a.wait_state(state)
        check(transitions(d)[-1] == n, "controlword 16#%02X: %s (%d), statusword 16#%04X"
              % (cw, sim.STATE_NAMES[state], n, sw))
        if state in (sim.SWITCHED_ON, sim.OPERATION_ENABLED):
            check(sw & 0x10, "  voltage enabled (bit 4)")
        if state in (sim.READY, sim.SWITCHED_ON, sim.OPERATION_ENABLED):
            check(sw & 0x20, "  quick stop bit (5) high: no quick stop")

    # Quick stop with option code 2: 11, then 12 once stopped.
    a.enable(8)
    a.controlword(0x02)
    sw = a.wait_state(sim.SWITCH_ON_DISABLED)
    check(transitions(d)[-2:] == [11, 12], "quick stop (option 2): 11 then 12 by itself")
    # Option code 6: stays in Quick stop active; 16 back; 12 by Disable voltage.
    a.write(sim.HR_QUICK_STOP_OPTION, [6])
    a.enable(8)
    a.controlword(0x02)
    sw = a.wait_state(sim.QUICK_STOP)
    check(not sw & 0x20, "Quick stop active: bit 5 low")
    time.sleep(0.2)
    check(decode(a.actual()["statusword"]) == sim.QUICK_STOP, "option 6: stays in Quick stop active")
    check(a.actual()["statusword"] & 0x0400, "  target reached (bit 10) once stopped")
    a.controlword(0x0F)
    a.wait_state(sim.OPERATION_ENABLED)
    check(transitions(d)[-1] == 16, "Enable operation from Quick stop active (16)")
    a.controlword(0x02)
    a.wait_state(sim.QUICK_STOP)
    a.controlword(0x00)
    a.wait_state(sim.SWITCH_ON_DISABLED)
    check(transitions(d)[-1] == 12, "Disable voltage from Quick stop active (12)")

    # Fault: 13, 14; the reset is the rising edge of bit 7 (15).
    a.enable(8)
    d.ok("fault 0x7300")
    sw = a.wait_state(sim.FAULT)
    check(transitions(d)[-2:] == [13, 14], "injected fault: 13, 14; statusword 16#%04X" % sw)
    check(a.actual()["error_code"] == 0x7300, "error code 603Fh = 16#7300")
    a.controlword(0x00)
    time.sleep(0.02)
    a.controlword(0x80)
    a.wait_state(sim.SWITCH_ON_DISABLED)
    check(transitions(d)[-1] == 15, "fault reset on the edge of bit 7 (15)")
    check(a.actual()["error_code"] == 0, "error code cleared by the reset")
    # A persistent fault survives resets until its cause is cleared.
    a.enable(8)
    d.ok("fault 0x4310 persist")
    a.wait_state(sim.FAULT)
    for _ in range(2):
        a.controlword(0x00)
        time.sleep(0.02)
        a.controlword(0x80)
        time.sleep(0.05)
        check(decode(a.actual()["statusword"]) == sim.FAULT, "persistent fault: the reset does not clear it")
    d.ok("fault clear")
    a.controlword(0x80)  # bit 7 already high: no edge
    time.sleep(0.05)
    check(decode(a.actual()["statusword"]) == sim.FAULT, "bit 7 held high is no edge")
    a.controlword(0x00)
    time.sleep(0.02)
    a.controlword(0x80)
    a.wait_state(sim.SWITCH_ON_DISABLED)
    check(True, "cleared cause: the next edge resets")
    # Bad commands on stdin are refused, the drive runs on.
    check(d.command("fault 0").startswith("error"), "fault 0 refused")
    check(d.command("garbage nonsense").startswith("error"), "unknown garbage mode refused")
    check(d.command("jump").startswith("error"), "unknown command refused")
    a.close()
    check(d.stop() == 0, "SIGTERM: clean stop")


if __name__ == "__main__":
    main()
