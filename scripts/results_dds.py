#!/usr/bin/python3
"""docs/results.md section 6: paper 000's four-axis table on five DDS nodes
(projects/four_axis_dds, docs/four-axis-dds.md) beside the in-process ring
(projects/four_axis_table/sync.yaml), at 0, 1, 5 and 20 % loss, with the
Taylor estimators and with a hold (order 0) in their place:

  ring      `syncplc sim projects/four_axis_table/sync.yaml --set ring.loss.p=P`
            (frame loss: every node loses the same frame);
  virtual   `syncplc sim projects/four_axis_dds/system.yaml` (the five nodes
            in one process, virtual time, the simulated bus; each axis node
            loses P of the samples it takes, drawn on its own);
  loopback  scripts/four_axis_dds.py: five `syncplc run` processes on
            loopback over Cyclone DDS, one 1 ms CLOCK_REALTIME grid, the
            loss injected in each axis node's receive thread;
  netns     the same, each node in a network namespace of its own, the
            five veths on one bridge (scripts/four_axis_dds.py --netns; root).

Usage: results_dds.py [--runs N]   (N real-time runs per cell, default 1)
Prints the markdown table; run from the repository root after a build.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

SYNCPLC = os.environ.get("SYNCPLC", "build/syncplc")
LOSSES = ["0", "0.01", "0.05", "0.2"]


def ring(loss, hold):
    sets = ["--set", "ring.loss.p=" + loss]
    if hold:
        for k in range(1, 5):
            for w in "xva":
                sets += ["--set", "n%d_%s.order=0" % (k, w)]
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "m.json")
        subprocess.run([SYNCPLC, "sim", "projects/four_axis_table/sync.yaml", "-d", "6.283185s", "-q", "--metrics", out]
                       + sets, check=True, stdout=subprocess.DEVNULL)
        m = json.load(open(out))["metrics"]
    return m["track_rsme"], m["sync_rsme"]


def virtual(loss, hold):
    sets = []
    for k in range(1, 5):
        sets += ["--set", "axis%d.net.inject.loss=%s" % (k, loss)]
        if hold:
            for w in "xva":
                sets += ["--set", "axis%d.n%d_%s.order=0" % (k, k, w)]
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "m.json")
        subprocess.run([SYNCPLC, "sim", "projects/four_axis_dds/system.yaml", "-d", "6.783185s", "-q", "--metrics", out]
                       + sets, check=True, stdout=subprocess.DEVNULL)
        m = json.load(open(out))["nodes"]["master"]["metrics"]
    return m["track_rsme"], m["sync_rsme"]


def loopback(loss, hold, runs, netns=False):
    got = []
    for i in range(runs):
        args = ["/usr/bin/python3", "scripts/four_axis_dds.py", "--json", "--build-dir", os.path.dirname(SYNCPLC),
                "--loss", loss, "--seed", str(7 + 10 * i)] + (["--netns"] if netns else [])
        if hold:
            args.append("--hold")
        p = subprocess.run(args, capture_output=True, text=True)
        if p.returncode != 0:  # a failed run is shown, not hidden
            sys.stderr.write(p.stdout + p.stderr)
            got.append(None)
            continue
        r = json.loads(p.stdout)
        # Gaps the axis nodes' subscriptions saw: the injected drops and the network's own.
        lost = sum(n["dds"].get("samples_lost", 0) for name, n in r["nodes"].items() if name != "master")
        got.append((r["track_rsme"], r["sync_rsme"], r["samples"], r["skipped"], lost))
    return got


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=1)
    args = ap.parse_args()
    print("| loss | reference words | ring: Track / Sync (rad) | DDS, virtual time: Track / Sync (rad) | "
          "DDS, 5 processes on loopback: Track / Sync (rad) | loopback: samples judged / skipped, axis samples lost | "
          "DDS, 5 network namespaces: Track / Sync (rad) |")
    print("|---:|---|---:|---:|---:|---|---:|")
    for loss in LOSSES:
        for hold in (False, True):
            rt, rs = ring(loss, hold)
            vt, vs = virtual(loss, hold)
            lb = loopback(loss, hold, args.runs)
            ns = loopback(loss, hold, 1, netns=True) if os.geteuid() == 0 else [None]
            cell = "<br>".join("%.6f / %.6f" % x[:2] if x else "failed" for x in lb)
            judged = "<br>".join("%d / %d, %d" % x[2:] if x else "failed" for x in lb)
            nscell = "<br>".join("%.6f / %.6f" % x[:2] if x else "—" for x in ns)
            print("| %g %% | %s | %.6f / %.6f | %.6f / %.6f | %s | %s | %s |" %
                  (float(loss) * 100, "hold" if hold else "Taylor", rt, rs, vt, vs, cell, judged, nscell))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
