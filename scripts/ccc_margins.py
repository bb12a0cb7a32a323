#!/usr/bin/python3
"""Gain and phase margin of the cross-coupled contour loop of
projects/paper002_servo (paper 003 Fig. 12's question for syncplc's loop
model; docs/results.md section 5).

Per axis (nominal drive of the project): P(s) = K e^{-s (d + Ts/2)} / (s (tau s + 1)),
a velocity-mode drive K/(tau s + 1) integrated to position, the actuation
delay d and the zero-order hold's half period; the axis's PI position loop
C(s) = Kp (1 + 1/(Ti s)). The CCC correction is added to the axis command,
so the contour error sees the closed axis loop P/(1 + C P), and with unit
coupling gains (|(Cx, Cy)| = 1) the CCC loop is
    L(s) = Kc P(s) / (1 + C(s) P(s)).
Margins are read off L(jw) on a log grid (numpy only): the gain margin at
every phase crossing of -180 deg, the phase margin (the angle between L and
-1) at every crossing of |L| = 1; the smallest of each is printed. A
negative gain margin means the contour loop is unstable.

usage: scripts/ccc_margins.py [--ts 0.001] GAIN...
"""
import argparse

import numpy as np


def margins(kc, ts, k=0.05, tau=0.0025, d=200e-6, kp=1000.0, ti=1.0):
    w = np.logspace(-1, np.log10(np.pi / ts), 200000)  # up to the Nyquist frequency
    s = 1j * w
    p = k * np.exp(-s * (d + ts / 2)) / (s * (tau * s + 1))
    c = kp * (1 + 1 / (ti * s))
    loop = kc * p / (1 + c * p)
    mag = np.abs(loop)
    ph = np.unwrap(np.angle(loop))
    gm = []
    for i in np.nonzero(np.diff(np.floor((ph + np.pi) / (2 * np.pi))))[0]:  # crossings of -180 deg (mod 360)
        gm.append(-20 * np.log10(mag[i]))
    pm = []
    for i in np.nonzero(np.diff(np.sign(mag - 1)))[0]:
        pm.append(180 - abs(np.degrees(np.angle(loop[i]))))  # the angle from -180 deg, either way round
    return (min(gm) if gm else float("inf")), (min(pm) if pm else float("inf"))


def main():
    a = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--ts", type=float, default=0.001, help="sampling period, s")
    a.add_argument("gains", type=float, nargs="+")
    o = a.parse_args()
    print("| CCC gain (V/m) | gain margin (dB) | phase margin (deg) |")
    print("|---|---|---|")
    for g in o.gains:
        gm, pm = margins(g, o.ts)
        print(f"| {g:g} | {gm:.2f} | {pm:.1f} |")


if __name__ == "__main__":
    main()
