#!/usr/bin/python3
"""docs/results.md section 3, "Paper 003 Figs. 7 and 8": the dropout
compensators (zero fill, hold, the paper's recursive Taylor, the robust
Taylor, the Wiener predictor, Ling & Lemmon's optimal compensator) in the
loop of paper 003 Fig. 3, run through projects/paper003_compensators with
`syncplc sim`; the optimal compensator's taps for each rate, and the exact
output powers beside the simulated ones, from `syncplc design-compensator`.

Usage: results_dropout.py tables OUTDIR     print the two tables, draw docs/figures/paper003_fig7.png, _fig8.png
       results_dropout.py loop_autocorrelation   the design lags rho1..rho4 of noise.yaml's Wiener predictor
Run by scripts/results.sh.
"""
import csv
import json
import math
import os
import subprocess
import sys

SYNCPLC = "build/syncplc"
NAMES = ["zero fill", "hold (1-delay)", "Taylor, recursive (paper)", "Taylor, robust", "Wiener predictor",
         "optimal (Ling & Lemmon)"]
LOOP = "projects/paper003_compensators/loop_model.yaml"
RATES = ["0", "0.05", "0.1", "0.15", "0.2", "0.3", "0.4", "0.5", "0.6"]
# Paper 003 §4.1: the identified DYNA plant P(z) = B(z)/A(z) (powers of z^-1).
PLANT_B = [0, 0, 0.30554, -0.023766, 0.11104, 0.028834]
PLANT_A = [1, -0.70669, 0.1934, -0.15112, -0.02566, 0.028011]


def loop_autocorrelation(n_lags=4, k_gain=1.0, steps=20000):
    """R_yy(j), j = 0..n_lags, of the loop of loop.st (u = K (r - y[k-1]),
    y = P u) for unit white noise r and no dropouts: from its impulse response h,
    R(j) = sum_i h_i h_(i+j)."""
    u = [0.0] * 6
    y = [0.0] * 6
    h = []
    for k in range(steps):
        r = 1.0 if k == 0 else 0.0
        u = [k_gain * (r - y[0])] + u[:-1]
        yk = sum(PLANT_B[i] * u[i] for i in range(6)) - sum(PLANT_A[i] * y[i - 1] for i in range(1, 6))
        y = [yk] + y[:-1]
        h.append(yk)
    return [sum(h[i] * h[i + j] for i in range(steps - j)) for j in range(n_lags + 1)]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return {h: [float(r[i]) for r in rows[1:]] for i, h in enumerate(rows[0])}


def sim(project, duration, out, sets):
    args = [SYNCPLC, "sim", project, "-q", "-d", duration, "--metrics", out + ".json", "--trace", out + ".csv"]
    for s in sets:
        args += ["--set", s]
    # stderr: a diverged loop (recursive Taylor) logs a block fault per scan once its output is not finite.
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return json.load(open(out + ".json")), read(out + ".csv")


def design(eps):
    """Ling & Lemmon's taps at this rate and the exact E[y^2] of zero fill,
    hold, the recursive Taylor taps and the optimum (syncplc design-compensator)."""
    out = subprocess.run([SYNCPLC, "design-compensator", LOOP, "--loss", eps, "--order", "4", "--taps", "4,-6,4,-1",
                          "--json"], check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    exact = {c["name"]: c["output_power"] for c in j["compare"]}
    return j["optimal"]["taps"], {"zero": exact["zero fill"], "hold": exact["hold (1-delay)"], "taylor": exact["given"],
                                  "optimal": j["optimal"]["output_power"]}


def fmt(x):
    return "diverges" if not math.isfinite(x) or x > 1e12 else f"{x:.4g}"


def run(kind, outdir):
    """{rate: ([index per compensator], ideal index, frames lost)}"""
    project = f"projects/paper003_compensators/{kind}.yaml"
    duration = "100s" if kind == "noise" else "20s"
    res = {}
    for eps in RATES:
        taps, exact = design(eps)
        sets = [f"ring.loss.p={eps}", f"wiener.dropout_rate={eps}"] + [f"optimal.a{i + 1}={a!r}" for i, a in enumerate(taps)]
        m, c = sim(project, duration, os.path.join(outdir, f"p003_{kind}_{eps}"), sets)
        # A diverged run (the recursive Taylor above ~12 % loss) has rms_error null (NaN) or huge.
        axes = [a["rms_error"] if a["rms_error"] is not None else float("inf") for a in m["metrics"]["axes"]]
        lost = int(next(d for d in m["drivers"] if d["name"] == "ring")["counters"]["frames_lost"])
        if kind == "noise":
            ideal = c["y_ideal"][1000:]
            res[eps] = ([a * a for a in axes], sum(v * v for v in ideal) / len(ideal), lost, exact, taps)
        else:
            e = c["e_ideal"][10:]
            res[eps] = (axes, math.sqrt(sum(v * v for v in e) / len(e)), lost, exact, taps)
    return res


def plot(res, ylabel, title, out, ideal_label):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    x = [float(e) for e in RATES]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for i, name in enumerate(NAMES):
        # Log scale: a diverged run (not finite, > 1e12) and a zero (no loss, Fig. 8) are left out.
        ys = [v if math.isfinite(v) and 0 < v < 1e12 else float("nan") for v in (res[e][0][i] for e in RATES)]
        ax.plot(x, ys, marker="o", label=name)
    if ideal_label:
        ax.plot(x, [res[e][1] for e in RATES], "k--", label=ideal_label)
    ax.set_yscale("log")
    ax.set_xlabel("dropout rate")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def exact_fmt(x):
    return "unbounded" if x is None else f"{x:.4g}"


def tables(outdir):
    os.makedirs(outdir, exist_ok=True)
    noise = run("noise", outdir)
    print("### 3b. Paper 003 Fig. 7: output power R_yy(0) with white-noise input (100 s)\n")
    print("| dropout rate | frames lost | " + " | ".join(NAMES) + " | optimal vs hold | optimal vs zero fill |")
    print("|---:|---:|" + "---:|" * (len(NAMES) + 2))
    for eps in RATES:
        v, _, lost, _, _ = noise[eps]
        print(f"| {float(eps):g} | {lost} | " + " | ".join(fmt(x) for x in v) +
              f" | {100 * (v[5] / v[1] - 1):+.1f} % | {100 * (v[5] / v[0] - 1):+.2f} % |")
    print(f"\nno dropouts: R_yy(0) = {noise['0'][1]:.4g}; theory (impulse response): {loop_autocorrelation()[0]:.4g}\n")
    print("Exact stationary E[y^2] (`syncplc design-compensator`) and the optimal taps:\n")
    print("| dropout rate | zero fill | hold | Taylor, recursive | optimal | optimal taps a1..a4 |")
    print("|---:|---:|---:|---:|---:|---|")
    for eps in RATES:
        x, taps = noise[eps][3], noise[eps][4]
        taps_text = ", ".join(f"{a:.3f}" for a in taps) if float(eps) > 0 else "any (nothing is lost)"
        print(f"| {float(eps):g} | " + " | ".join(exact_fmt(x[k]) for k in ("zero", "hold", "taylor", "optimal")) +
              " | " + taps_text + " |")
    print(f"\ncommand: `{SYNCPLC} design-compensator {LOOP} --loss EPS --taps 4,-6,4,-1`, then "
          f"`{SYNCPLC} sim projects/paper003_compensators/noise.yaml -d 100s --set ring.loss.p=EPS "
          "--set wiener.dropout_rate=EPS --set optimal.a1=A1 ... --set optimal.a4=A4 --metrics out.json` "
          "(R_yy = metrics.axes[i].rms_error^2)\n")
    sin = run("sinusoid", outdir)
    print("### 3c. Paper 003 Fig. 8: sinusoid 50 mm at 3000 mm/min, RMS of y minus the loss-free loop's y (mm, 20 s)\n")
    print("| dropout rate | frames lost | " + " | ".join(NAMES) + " |")
    print("|---:|---:|" + "---:|" * len(NAMES))
    for eps in RATES:
        v, _, lost, _, _ = sin[eps]
        print(f"| {float(eps):g} | {lost} | " + " | ".join(fmt(x) for x in v) + " |")
    print(f"\nloss-free loop: RMS tracking error r - y = {sin['0'][1]:.4g} mm\n")
    print(f"command: `{SYNCPLC} sim projects/paper003_compensators/sinusoid.yaml -d 20s --set ring.loss.p=EPS "
          "--set wiener.dropout_rate=EPS --set optimal.a1=A1 ... --metrics out.json` (metrics.axes[i].rms_error)\n")
    plot(noise, "R_yy(0) = E[y^2]", "Paper 003 Fig. 7: white-noise input", "docs/figures/paper003_fig7.png",
         "no dropouts")
    plot(sin, "RMS(y - y without dropouts) (mm)", "Paper 003 Fig. 8: sinusoid 50 mm, 3000 mm/min",
         "docs/figures/paper003_fig8.png", None)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "tables":
        tables(sys.argv[2])
    elif len(sys.argv) == 2 and sys.argv[1] == "loop_autocorrelation":
        r = loop_autocorrelation()
        print(f"R_yy(0) = {r[0]:.6g}; " + ", ".join(f"rho{j}: {r[j] / r[0]:.6f}" for j in range(1, len(r))))
    else:
        sys.exit("usage: results_dropout.py tables OUTDIR | loop_autocorrelation")
