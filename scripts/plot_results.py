#!/usr/bin/python3
"""Figures for docs/results.md from `syncplc sim --trace` CSV files.

Usage: plot_results.py paper000 SYNC.csv PD.csv OUT.png
       plot_results.py paper004 ASYNC.csv SYNC.csv OUT.png N
Run by scripts/results.sh, which installs python3-matplotlib with apt-get.
"""
import csv
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


def paper004(async_csv, sync_csv, out, n):
    fig, ax = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    for row, (name, path) in enumerate([("asynchronous (rule off)", async_csv), ("synchronized (unified rule)", sync_csv)]):
        c = read(path)
        t = c["time_s"]
        for i in range(1, n + 1):
            line, = ax[row].plot(t, c[f"sync.x[{i}]"], lw=1.0, label=f"x{i}")
            ax[row].plot(t, c[f"r[{i}]"], lw=0.6, ls="--", color=line.get_color())
        ax[row].set_title(name)
        ax[row].grid(alpha=0.3)
        ax[row].set_ylabel("position (m)")
        ax[row].legend(fontsize=7, loc="upper right")
    ax[1].set_xlabel("time (s)")
    fig.suptitle("Paper 004: filtered references (solid) and rough references (dashed)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    if sys.argv[1] == "paper000":
        paper000(sys.argv[2], sys.argv[3], sys.argv[4])
    elif sys.argv[1] == "paper004":
        paper004(sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5]))
    else:
        sys.exit("usage: plot_results.py paper000|paper004 ...")
