#!/usr/bin/python3
"""docs/results.md section 5, "Paper 002: the servo test's contour error" and
its paper 003 Figs. 11-15 subsections: the circle of paper 002's servo test and
the ellipse of the robust CCC, with and without CCC_2AXIS and frame loss, run
through projects/paper002_servo with `syncplc sim`; the margins of the contour
loop from scripts/ccc_margins.py.

Usage: results_contour.py tables OUTDIR     print section 5's tables (metrics land in OUTDIR)
The binary: $SYNCPLC, default build/syncplc. Run by scripts/results.sh.
"""
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ccc_margins import margins  # noqa: E402

SYNCPLC = os.environ.get("SYNCPLC", "build/syncplc")
P = "projects/paper002_servo/"
LOSS = ["ring.loss.p=0.1997"]
HOLD = LOSS + [f"{e}.order=0" for e in ("est_x", "est_vx", "est_ax", "est_y", "est_vy", "est_ay")]
ROBUST = ["ccc.robust=TRUE", "ccc.gain_low=4000", "ccc.gain=20000"]
OUTDIR = "/tmp/syncplc-results"


def sim(project, duration, sets):
    out = os.path.join(OUTDIR, "p002_" + "_".join([project[:-5]] + sets).replace("=", "-") + ".json")
    args = [SYNCPLC, "sim", P + project, "-q", "-d", duration, "--metrics", out]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    return json.load(open(out))["metrics"]


def mm(x):
    # Four decimals (µm and below); three significant digits once the loop oscillates (>= 0.1 mm).
    return f"{1000 * x:.4f}" if 1000 * x < 0.1 else f"{1000 * x:.3g}"


def circle(project, duration, sets):
    """contour error mean |.| / max / RMS (mm) of the measured point from the programmed circle"""
    c = sim(project, duration, sets)["contour_error"]
    return [mm(c["mean_abs"]), mm(c["max_abs"]), mm(c["rms"])]


def ellipse(project, sets):
    """max / RMS (mm) of CCC_2AXIS's estimated contour error, the project's one metric axis (eps)"""
    a = sim(project, "8s", sets)["axes"][0]
    return [mm(a["max_abs_error"]), mm(a["rms_error"])]


def margin_cells(gain):
    if gain == 0:
        return ["—", "—"]
    gm, pm = margins(gain, 0.001)
    if gm < -1:
        return ["unstable", ""]
    # A margin just below zero keeps two decimals so that its sign shows.
    return [f"{gm:.1f}" if gm >= 0 else f"−{-gm:.2f}", f"{pm:.1f}"]


def row(cells):
    print(("| " + " | ".join(cells) + " |").replace("|  |", "| |"))


def tables():
    print("### 5. Paper 002: the servo test's contour error\n")
    print("| run | contour error mean (mm) | max (mm) | RMS (mm) | paper 002 mean / max (mm) |")
    print("|---|---:|---:|---:|---|")
    for label, project, duration, gain, paper in [
            ("4 ms, 2500 mm/min, no CCC", "servo_4ms.yaml", "49s", 0, "0.0036 / 0.0187"),
            ("4 ms, CCC gain 4000 V/m", "servo_4ms.yaml", "49s", 4000, "—"),
            ("1 ms, 10000 mm/min, no CCC", "servo_1ms.yaml", "12.5s", 0, "0.0049 / 0.0219"),
            ("1 ms, CCC gain 4000 V/m", "servo_1ms.yaml", "12.5s", 4000, "—"),
            ("1 ms, CCC gain 20000 V/m", "servo_1ms.yaml", "12.5s", 20000, "—")]:
        row([label] + circle(project, duration, [f"ccc.gain={gain}"] if gain else []) + [paper])
    print("| SERCOS (Guo et al., cited by paper 002) | | | | 0.0448 average |\n")

    print("### 5b. Paper 003 Figs. 11 and 12: contour error and stability margin against the CCC gain\n")
    print("| CCC gain (V/m), 1 ms | contour mean (mm) | max (mm) | RMS (mm) | gain margin (dB) | phase margin (°) |")
    print("|---:|---:|---:|---:|---:|---:|")
    for gain in [0, 1000, 2000, 4000, 10000, 20000, 30000, 40000]:
        row([str(gain)] + circle("servo_1ms.yaml", "12.5s", [f"ccc.gain={gain}"]) + margin_cells(gain))
    print()

    print("### 5c. Paper 003 Fig. 13: the circle with 19.97 % frame loss, contour error mean / max / RMS (mm)\n")
    print("| CCC gain (V/m) | no loss | 19.97 % loss, Taylor estimator | 19.97 % loss, hold |")
    print("|---:|---|---|---|")
    for gain in [0, 4000, 20000]:
        g = [f"ccc.gain={gain}"]
        row([str(gain)] + [" / ".join(circle("servo_1ms_network.yaml", "12.5s", s + g)) for s in ([], LOSS, HOLD)])
    print()

    print("### 5d. Paper 003 Fig. 14: the ellipse, fixed and robust CCC\n")
    print("| CCC | contour error max (mm) | RMS (mm) |")
    print("|---|---:|---:|")
    for label, sets in [("none", ["ccc.gain=0"]), ("fixed gain 4000 V/m", ["ccc.gain=4000"]),
                        ("fixed gain 20000 V/m", ["ccc.gain=20000"]),
                        ("robust: 4000 on the lines, 4000 + 16000·min(1, K/25)", ROBUST)]:
        row([label] + ellipse("ellipse_robust.yaml", sets))
    print()

    print("### 5e. Paper 003 Fig. 15: the ellipse with 19.97 % frame loss, contour error max / RMS (mm)\n")
    print("| CCC | no loss | 19.97 % loss, Taylor estimator | 19.97 % loss, hold |")
    print("|---|---|---|---|")
    for label, sets in [("fixed 4000 V/m", ["ccc.gain=4000"]), ("fixed 20000 V/m", ["ccc.gain=20000"]),
                        ("robust 4000 … 20000", ROBUST)]:
        row([label] + [" / ".join(ellipse("ellipse_network.yaml", s + sets)) for s in ([], LOSS, HOLD)])
    print()


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "tables":
        OUTDIR = sys.argv[2]
        os.makedirs(OUTDIR, exist_ok=True)
        tables()
    else:
        sys.exit("usage: results_contour.py tables OUTDIR")
