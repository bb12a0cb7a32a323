"""The simulated CiA 402 drive integrates the same plant as sim_table: the
project plant_compare.yaml runs sim_table under `syncplc sim` on an open-loop
command sequence (cut by the +-1 PWM limit); the drive's AxisPlant, with
the drive's defaults for each --axis, is stepped on the same (limited)
commands, and positions and velocities must agree sample by sample. Then the
drive itself, cycled in-process in cyclic synchronous torque, must move its
plant exactly as AxisPlant does.

    /usr/bin/python3 tests/drives/test_sim_drive_plant.py build/syncplc
"""

import csv
import os
import subprocess
import sys
import tempfile

from drivelib import HERE, check, sim


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: /usr/bin/python3 %s PATH/TO/syncplc" % sys.argv[0])
    syncplc = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        trace = os.path.join(tmp, "trace.csv")
        env = dict(os.environ, XDG_STATE_HOME=tmp)
        subprocess.run([syncplc, "sim", os.path.join(HERE, "plant_compare.yaml"), "-d", "3s", "--trace", trace, "-q"],
                       check=True, env=env, stdout=subprocess.DEVNULL, timeout=120)
        with open(trace) as f:
            rows = list(csv.DictReader(f))
    check(len(rows) == 3000, "sim_table trace: 3000 samples of 1 ms")
    saturated = sum(1 for r in rows if abs(float(r["cmd[1]"])) > 1)
    check(saturated > 500, "the command sequence is cut by the limit in %d samples" % saturated)
    for axis in range(1, 5):
        a = sim.parse_args(["--axis", str(axis)])
        check(a.saturation == 1.0 and a.rate == 1000.0, "axis %d: the drive's defaults: 1 PWM, 1 kHz" % axis)
        plant = sim.AxisPlant(a.tau, a.gain, 1.0 / a.rate)
        worst_x = worst_v = 0.0
        for k, r in enumerate(rows):
            # Row k: the state sampled at the start of scan k, and the command
            # that scan wrote (acting from then on, zero-order hold).
            x, v = float(r["pos[%d]" % axis]), float(r["vel[%d]" % axis])
            worst_x = max(worst_x, abs(plant.position - x) / (1 + abs(x)))
            worst_v = max(worst_v, abs(plant.velocity - v) / (1 + abs(v)))
            u = max(-a.saturation, min(a.saturation, float(r["cmd[%d]" % axis])))
            plant.step(u)
        check(worst_x < 1e-9 and worst_v < 1e-9,
              "axis %d (tau %g, k %g): relative difference position %.1e, velocity %.1e"
              % (axis, a.tau, a.gain, worst_x, worst_v))

    # The drive in CST, cycled in-process: u = 6071h / torque_scale into the plant.
    a = sim.parse_args(["--axis", "3"])
    drive = sim.Drive(a)
    ref = sim.AxisPlant(a.tau, a.gain, 1.0 / a.rate)
    drive.hr.setValues(sim.HR_MODES, [10])
    for cw in (0x00,) * 20 + (0x06, 0x07, 0x0F):
        drive.hr.setValues(sim.HR_CONTROLWORD, [cw])
        drive.cycle()
    check(drive.state == sim.OPERATION_ENABLED, "in-process drive: Operation enabled in CST")
    worst = 0.0
    for k in range(2000):
        torque = [300, -700, 1000, 1500, -1500, 0][(k // 250) % 6]
        drive.hr.setValues(sim.HR_TARGET_TORQUE, [torque & 0xFFFF])
        drive.cycle()
        ref.step(max(-1.0, min(1.0, torque / 1000.0)))
        worst = max(worst, abs(drive.plant.position - ref.position), abs(drive.plant.velocity - ref.velocity))
    check(worst == 0.0, "CST: the drive's plant is AxisPlant on 6071h/1000, limited to 1 PWM (difference %g)" % worst)


if __name__ == "__main__":
    main()
