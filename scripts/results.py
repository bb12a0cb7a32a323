#!/usr/bin/python3
"""The numbers and figures of docs/results.md, from the shipped projects.

Usage: results.py tables OUTDIR      run every row, print Markdown tables, draw docs/figures/*.png
       results.py paper000 SYNC.csv PD.csv OUT.png
       results.py paper004 ASYNC.csv SYNC.csv OUT.png N
Run by scripts/results.sh, which installs python3-matplotlib with apt-get.
"""
import csv
import json
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], rows[1:]
    cols = {h: [float(r[i]) for r in data] for i, h in enumerate(head)}
    return cols


def sync_errors(e):
    """eps = T e, paper 000 eq. (6): eps_1 = 0, eps_k = e_k - mean(e_1..e_{k-1})."""
    n = len(e)
    out = [[0.0] * len(e[0])]
    for k in range(1, n):
        out.append([e[k][j] - sum(e[i][j] for i in range(k)) / k for j in range(len(e[0]))])
    return out


def paper000(sync_csv, pd_csv, out):
    fig, ax = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    for col, (name, path) in enumerate([("PD baseline", pd_csv), ("synchronous controller", sync_csv)]):
        c = read(path)
        t = c["time_s"]
        e = [c[f"e_true[{i}]"] for i in range(1, 5)]
        eps = sync_errors(e)
        for i in range(4):
            ax[0][col].plot(t, [1e3 * x for x in e[i]], lw=0.8, color=f"C{i}", label=f"axis {i + 1}")
            if i:
                ax[1][col].plot(t, [1e3 * x for x in eps[i]], lw=0.8, color=f"C{i}", label=f"axis {i + 1}")
        ax[0][col].set_title(f"{name}: position errors e_i")
        ax[1][col].set_title(f"{name}: synchronization errors eps_i")
        ax[0][col].set_ylabel("mrad")
        ax[1][col].set_ylabel("mrad")
        ax[1][col].set_xlabel("time (s)")
        for a in (ax[0][col], ax[1][col]):
            a.grid(alpha=0.3)
            a.axvspan(2, 4, color="0.9", zorder=0)
        ax[0][col].legend(fontsize=7, loc="upper right")
        ax[1][col].legend(fontsize=7, loc="upper right")
    fig.suptitle("Paper 000 Figs. 5-6 on the simulated table (grey: +0.05 PWM on axis 4)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def paper004(async_csv, sync_csv, out, n, window_s=None):
    fig, ax = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    for row, (name, path) in enumerate([("asynchronous (rule off)", async_csv), ("synchronized (unified rule)", sync_csv)]):
        c = read(path)
        t = c["time_s"]
        keep = [k for k, x in enumerate(t) if window_s is None or window_s[0] <= x <= window_s[1]]
        tt = [t[k] for k in keep]
        for i in range(1, n + 1):
            line, = ax[row].plot(tt, [c[f"sync.x[{i}]"][k] for k in keep], lw=1.0, label=f"x{i}")
            ax[row].plot(tt, [c[f"r[{i}]"][k] for k in keep], lw=0.6, ls="--", color=line.get_color())
        ax[row].set_title(name)
        ax[row].grid(alpha=0.3)
        ax[row].set_ylabel("position (m)")
        ax[row].legend(fontsize=7, loc="upper right")
    ax[1].set_xlabel("time (s)")
    fig.suptitle("Paper 004: filtered references (solid) and rough references (dashed)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


SYNCPLC = "build/syncplc"


def sim(project, duration, out, sets=(), trace=True, metrics=True):
    """Runs one simulation; returns (command, metrics dict or None, trace path or None)."""
    args = [SYNCPLC, "sim", project, "-q", "-d", duration]
    for s in sets:
        args += ["--set", s]
    shown = " ".join(args[:2] + [project, "-d", duration] + [f"--set {s}" for s in sets])
    m = t = None
    if metrics:
        m = out + ".json"
        args += ["--metrics", m]
    if trace:
        t = out + ".csv"
        args += ["--trace", t]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    return shown, (json.load(open(m)) if m else None), t


def pct(new, old):
    return f"{100.0 * (new / old - 1):+.1f} %"


def tables(outdir):
    os.makedirs(outdir, exist_ok=True)
    fa = "projects/four_axis_table/"
    period = "6.283185s"
    print("### 1-2. Paper 000: synchronous vs PD on the simulated table and ring\n")
    print("| run | Track-RSME (rad) | Sync-RSME (rad) | vs PD: Track | vs PD: Sync | frames lost | command |")
    print("|---|---:|---:|---:|---:|---:|---|")
    no_comp = ["ax2.compensation=FALSE", "ax3.compensation=FALSE", "ax4.compensation=FALSE"]
    rows = [("PD", "pd.yaml", []), ("synchronous", "sync.yaml", []),
            ("synchronous, no delay compensation", "sync.yaml", no_comp)]
    for loss in ("0.1", "0.2", "0.4"):
        rows.append((f"PD, {int(float(loss) * 100)} % frame loss", "pd.yaml", [f"ring.loss.p={loss}"]))
        rows.append((f"synchronous, {int(float(loss) * 100)} % frame loss", "sync.yaml", [f"ring.loss.p={loss}"]))
        rows.append((f"synchronous, {int(float(loss) * 100)} % frame loss, hold instead of Taylor",
                     "sync.yaml", [f"ring.loss.p={loss}"] + [f"n{i}_{w}.order=0" for i in range(1, 5) for w in "xva"]))
    pd = {}
    traces = {}
    for label, f, sets in rows:
        cmd, m, t = sim(fa + f, period, os.path.join(outdir, label.replace(" ", "_").replace(",", "").replace("%", "pc")), sets)
        mm = m["metrics"]
        lost = int(m["drivers"][1]["counters"]["frames_lost"])
        key = [s for s in sets if s.startswith("ring.")]
        if f == "pd.yaml":
            pd[tuple(key)] = mm
        base = pd.get(tuple(key))
        vs = (pct(mm["track_rsme"], base["track_rsme"]), pct(mm["sync_rsme"], base["sync_rsme"])) if base and f != "pd.yaml" else ("", "")
        print(f"| {label} | {mm['track_rsme']:.6f} | {mm['sync_rsme']:.6f} | {vs[0]} | {vs[1]} | {lost} | `{cmd}` |")
        if not sets:
            traces[f] = t
    paper000(traces["sync.yaml"], traces["pd.yaml"], "docs/figures/paper000_errors.png")

    print("\n### 3. Paper 003: transmission error under Bernoulli frame loss (20 s of the sinusoid)\n")
    print("| loss | zero-fill RMS (m) | hold RMS (m) | recursive Taylor RMS (m) | robust Taylor RMS (m) | closed loop: zero / hold / recursive / robust RMS (m) |")
    print("|---:|---:|---:|---:|---:|---|")
    for loss in ("0.01", "0.05", "0.1", "0.12", "0.15", "0.2", "0.3", "0.4", "0.5"):
        cmd, m, t = sim("projects/paper003_estimator/estimator.yaml", "20s", os.path.join(outdir, f"est_{loss}"),
                        [f"ring.loss.p={loss}"])
        a = m["metrics"]["axes"]
        c = read(t)
        cl = [math.sqrt(sum(x * x for x in c[f"cl[{i}]"][10:]) / len(c[f"cl[{i}]"][10:])) for i in range(1, 5)]
        print(f"| {float(loss) * 100:g} % | " + " | ".join(f"{x['rms_error']:.3g}" for x in a) + " | " +
              " / ".join(f"{x:.3g}" for x in cl) + " |")
    print(f"\ncommand: `{SYNCPLC} sim projects/paper003_estimator/estimator.yaml -d 20s --set ring.loss.p=LOSS --metrics out.json`\n")

    print("### 4. Paper 004: synchronized filters (Table II bounds, 600 s; six axes, 2000 s)\n")
    print("| project | rule | windows | windows with spread > 0 | max spread (scans) | E total (m^2/s) | E vs off | command |")
    print("|---|---|---:|---:|---:|---:|---:|---|")
    for proj, dur in (("three_signals", "600s"), ("six_axes", "2000s")):
        e_off = None
        tr = {}
        for rule, name in (("2", "off"), ("0", "unified"), ("1", "paper")):
            cmd, _, t = sim(f"projects/paper004_sync/{proj}.yaml", dur, os.path.join(outdir, f"{proj}_{name}"),
                            [f"sync.rule={rule}"], metrics=False)
            w = windows(t)
            e = sum(x[0] for x in w)
            if e_off is None:
                e_off = e
            spread = [x[1] for x in w]
            print(f"| {proj} | {name} | {len(w)} | {sum(1 for s in spread if s > 0)} | {max(spread) if spread else 0} | "
                  f"{e:.2f} | {pct(e, e_off) if name != 'off' else ''} | `{cmd}` |")
            tr[name] = t
        if proj == "three_signals":
            paper004(tr["off"], tr["unified"], "docs/figures/paper004_three_signals.png", 3, window_s=(0, 20))


def windows(trace):
    """(E, spread) of every closed transient window, from the sync.windows counter."""
    c = read(trace)
    out = []
    last = 0
    for k, w in enumerate(c["sync.windows"]):
        if w > last:
            out.append((c["sync.energy_last"][k], int(c["sync.spread"][k])))
            last = w
    return out


if __name__ == "__main__":
    if sys.argv[1] == "tables":
        tables(sys.argv[2])
    elif sys.argv[1] == "paper000":
        paper000(sys.argv[2], sys.argv[3], sys.argv[4])
    elif sys.argv[1] == "paper004":
        paper004(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
    else:
        sys.exit("usage: results.py tables OUTDIR | paper000 ... | paper004 ...")
