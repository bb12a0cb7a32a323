#!/usr/bin/python3
"""The jerk-limited PLCopen moves against a numerical optimum nobody here wrote.

For random moves from rest (random period, velocity, acceleration,
deceleration, jerk and distance) the helper plcopen_jerk_profile (argv[1])
prints the set values of MC_MoveAbsolute scan by scan. This script
  - checks them on its own: position, velocity, acceleration (the velocity's
    change over a scan / T) and jerk (the acceleration's change / T) within
    the limits at every scan, no overshoot, exact arrival at rest, and the
    remaining-scans figure given at the start equal to the scans taken;
  - finds the fewest scans N in which ANY sampled profile of the same model
    can make the move: GLPK's simplex (Debian's python3-cvxopt) on the discrete
    system  w[k+1] = w[k] + T a[k],  x[k+1] = x[k] + T (w[k] + w[k+1]) / 2,
    |w| <= V, -D <= a <= A, |a[k] - a[k-1]| <= J T with a = 0 before the start
    and after the arrival, w[0] = w[N] = 0, x[N] = goal; a feasibility LP,
    bisected on N (feasible in N means feasible in N + 1: rest one more scan);
  - requires the profile's arrival never below the LP's minimum (that would
    mean it broke a limit) and at most one jerk window (m scans, the
    window length of docs/motion/jerk-profile.md) above it.
Prints the largest gap seen. Exit 0 on success.
"""
import math
import random
import subprocess
import sys

from cvxopt import glpk, matrix, spmatrix

glpk.options["msg_lev"] = "GLP_MSG_OFF"

CASES = 40
REL = 1e-9  # rounding allowance on the limits, relative


def window_length(A, D, J, T):
    U = max(A, D)
    return max(1, math.ceil(2 * U / (J * T) * (1 - 1e-12)))


def feasible(N, T, V, A, D, J, dist):
    """Whether a move of `dist` (> 0) from rest to rest fits in N scans.

    Scaled variables: alpha[k] = a[k] / U (k < N), omega[k] = w[k] / V (k <= N).
    GLPK's simplex on  G x <= h,  E x = e  (a feasibility problem: c = 0).
    """
    if N < 1:
        return False
    U = max(A, D)
    nv = N + (N + 1)
    ia = lambda k: k  # noqa: E731
    iw = lambda k: N + k  # noqa: E731
    ev, er, ec, e = [], [], [], []
    c = T * U / V
    for k in range(N):  # omega[k+1] - omega[k] - c alpha[k] = 0
        ev += [1.0, -1.0, -c]
        er += [k, k, k]
        ec += [iw(k + 1), iw(k), ia(k)]
        e.append(0.0)
    for k in range(N + 1):  # sum_k (omega[k] + omega[k+1]) = 2 dist / (T V)
        ev.append(2.0 if 0 < k < N else 1.0)
        er.append(N)
        ec.append(iw(k))
    e.append(2 * dist / (T * V))
    for k in (0, N):  # at rest at the start and at the arrival
        ev.append(1.0)
        er.append(len(e))
        ec.append(iw(k))
        e.append(0.0)
    gv, gr, gc, h = [], [], [], []

    def le(coefs, bound):
        r = len(h)
        for col, val in coefs:
            gv.append(val)
            gr.append(r)
            gc.append(col)
        h.append(bound)

    jt = J * T / U
    for k in range(N):
        lo, hi = -D / U, A / U
        if k == 0 or k == N - 1:  # a = 0 before the start and after the arrival
            lo, hi = max(lo, -jt), min(hi, jt)
        le([(ia(k), 1.0)], hi)
        le([(ia(k), -1.0)], -lo)
        if k > 0:
            le([(ia(k), 1.0), (ia(k - 1), -1.0)], jt)
            le([(ia(k), -1.0), (ia(k - 1), 1.0)], jt)
    for k in range(1, N):
        le([(iw(k), 1.0)], 1.0)
        le([(iw(k), -1.0)], 1.0)
    G = spmatrix(gv, gr, gc, (len(h), nv))
    E = spmatrix(ev, er, ec, (len(e), nv))
    status = glpk.lp(matrix(0.0, (nv, 1)), G, matrix(h), E, matrix(e))[0]
    return status == "optimal"


def lp_minimum(hi, T, V, A, D, J, dist):
    """Fewest scans; hi must be feasible (the profile's own count)."""
    if not feasible(hi, T, V, A, D, J, dist):
        return None
    lo = 0  # infeasible (a move needs at least one scan)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if feasible(mid, T, V, A, D, J, dist):
            hi = mid
        else:
            lo = mid
    return hi


def check_profile(case, predicted, scans, rows):
    T, V, A, D, J, x0, goal = case
    fails = []
    if predicted != scans:
        fails.append(f"remaining_scans at the start {predicted}, scans taken {scans}")
    x = [r[0] for r in rows]
    v = [r[1] for r in rows]
    if x[-1] != goal or v[-1] != 0:
        fails.append(f"ends at {x[-1]!r}, {v[-1]!r}, not exactly at {goal} at rest")
    sgn = 1 if goal > x0 else -1
    a = [0.0] + [(v[k + 1] - v[k]) / T for k in range(len(v) - 1)] + [0.0]
    for k in range(len(rows)):
        if abs(v[k]) > V * (1 + REL):
            fails.append(f"scan {k}: |v| {v[k]} above {V}")
            break
        if sgn * (x[k] - goal) > 1e-12 * max(1, abs(goal)):
            fails.append(f"scan {k}: overshoot {x[k]} past {goal}")
            break
        if k + 1 < len(rows):
            step = T * (v[k] + v[k + 1]) / 2
            if abs(x[k + 1] - x[k] - step) > 1e-9 * max(1, abs(x[k])):
                fails.append(f"scan {k}: position does not follow x' = x + T (v + v')/2")
                break
    hi_a, lo_a = (A, -D) if sgn > 0 else (D, -A)
    for k, ak in enumerate(a):
        if ak > hi_a * (1 + 1e-6) or ak < lo_a * (1 + 1e-6):
            fails.append(f"scan {k}: acceleration {ak} outside [{lo_a}, {hi_a}]")
            break
    for k in range(len(a) - 1):
        if abs(a[k + 1] - a[k]) / T > J * (1 + 1e-6):
            fails.append(f"scan {k}: jerk {(a[k + 1] - a[k]) / T} above {J}")
            break
    return fails


def main():
    tool = sys.argv[1]
    rng = random.Random(24)
    cases = []
    for _ in range(CASES):
        T = rng.choice([0.001, 0.002, 0.004])
        V = rng.uniform(0.3, 3)
        A = rng.uniform(5, 60)
        D = rng.uniform(5, 60)
        m = rng.randint(2, 40)  # the window the jerk asks for, roughly
        J = 2 * max(A, D) / (m * T) * rng.uniform(0.8, 1.2)
        x0 = rng.uniform(-1, 1)
        dist = rng.choice([rng.uniform(0.0005, 0.02), rng.uniform(0.02, 0.3), rng.uniform(0.3, 1.5)])
        goal = x0 + rng.choice([1, -1]) * dist
        cases.append((T, V, A, D, J, x0, goal))
    text = "".join(" ".join(repr(c) for c in case) + "\n" for case in cases)
    out = subprocess.run([tool], input=text, capture_output=True, text=True, timeout=300)
    if out.returncode != 0:
        print(out.stderr)
        return 1
    lines = out.stdout.splitlines()
    pos = 0
    failures = 0
    worst = (0, None)
    for case in cases:
        head = lines[pos].split()
        pos += 1
        if head[0] != "case":
            print("FAIL", case, "refused:", lines[pos - 1])
            failures += 1
            continue
        predicted, scans = int(head[1]), int(head[2])
        rows = [tuple(float(t) for t in lines[pos + k].split()) for k in range(scans + 1)]
        pos += scans + 1
        T, V, A, D, J, x0, goal = case
        fails = check_profile(case, predicted, scans, rows)
        # The LP is mirror-symmetric: a move in - is the move in + with A and D swapped.
        dist = abs(goal - x0)
        la, ld = (A, D) if goal > x0 else (D, A)
        n_lp = lp_minimum(scans, T, V, la, ld, J, dist)
        m = window_length(A, D, J, T)
        if n_lp is None:
            fails.append(f"the LP finds no profile in {scans} scans: the profile broke a limit")
        else:
            gap = scans - n_lp
            if gap < 0:
                fails.append(f"arrives in {scans} scans, below the LP minimum {n_lp}")
            if gap > m:
                fails.append(f"arrives in {scans} scans, {gap} above the LP minimum {n_lp} (window {m})")
            if gap > worst[0]:
                worst = (gap, (case, scans, n_lp, m))
            print(f"T={T} V={V:.3f} A={A:.2f} D={D:.2f} J={J:.1f} dist={dist:.5f}: "
                  f"{scans} scans, LP minimum {n_lp}, gap {gap}, window {m}")
        for f in fails:
            print("FAIL", case, f)
        failures += bool(fails)
    print(f"largest gap to the LP minimum: {worst[0]} scans ({worst[1]})")
    print(f"{len(cases) - failures} of {len(cases)} cases pass")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
