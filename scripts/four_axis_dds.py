#!/usr/bin/python3
"""Run the four-axis table on five DDS nodes (projects/four_axis_dds/,
docs/four-axis-dds.md) on this machine: five `syncplc run` processes on
loopback, the master and four axis nodes, each with its own HTTP port (a
free one), PLC database and the launcher's own DDS domain, on one 1 ms grid
(--align 1ms). It waits until the master's metrics window is complete, reads
the master's result tags over the HTTP API, prints Track-RSME, Sync-RSME,
the samples counted and skipped and each node's DDS counters (printed by
each `syncplc run` when it stops), and stops every process (SIGTERM, then
SIGKILL), also on an error or Ctrl-C.

    scripts/four_axis_dds.py                         # one cosine period, no loss
    scripts/four_axis_dds.py --loss 0.05             # 5 % of the samples each axis node takes lost
    scripts/four_axis_dds.py --loss 0.05 --hold      # the estimators replaced by a hold (order 0)
    scripts/four_axis_dds.py --json                  # one JSON object for a results script

    scripts/four_axis_dds.py --netns                 # each node in a network namespace of its own (root)

--netns: five network namespaces, each node's veth joined to a bridge the
launcher makes, 10.77.N.1-5/24, unicast peers, the HTTP API on the node's
address; all of it removed at the end. A machine per node, as far as the
network goes (one kernel, one clock).

Options: --build-dir DIR (where syncplc is, default build), --loss P,
--seed S (of the injection; axis k uses S + k), --hold, --duration D (the
window, default 6.283185s: one period), --domain N, --keep DIR (the nodes'
databases and logs kept there), --json.
"""

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROJECT_DIR = os.path.join(ROOT, "projects", "four_axis_dds")
NODES = ["axis1", "axis2", "axis3", "axis4", "master"]
RESULTS = ["track_rsme", "sync_rsme", "samples", "skipped", "lag_max", "lagged", "max_abs_e", "ref_dev",
           "window_from", "window_scans", "master_scan", "cos_start"]


def duration_s(text):
    for suffix, f in (("ms", 1e-3), ("us", 1e-6), ("s", 1.0)):
        if text.endswith(suffix):
            return float(text[:-len(suffix)]) * f
    return float(text)


class Node:
    """One `syncplc run` of the table; its HTTP port from the line it prints."""

    def __init__(self, syncplc, name, workdir, sets, limit_s, netns=None, host="127.0.0.1"):
        self.name = name
        self.host = host
        self.log_path = os.path.join(workdir, name + ".log")
        self.out_path = os.path.join(workdir, name + ".out")
        args = ["ip", "netns", "exec", netns] if netns else []
        args += [syncplc, "run", os.path.join(PROJECT_DIR, name + ".yaml"), "--align", "1ms", "--no-status",
                 "--http", host + ":0", "--http-anonymous-read", "on", "--db", os.path.join(workdir, name + ".db"),
                 "-d", "%ds" % limit_s]
        if netns:
            args.append("--http-insecure")  # an address beyond loopback: the launcher's own bridge
        for s in sets:
            args += ["--set", s]
        self.args = args
        self.out = open(self.out_path, "w")
        self.proc = subprocess.Popen(args, stdout=self.out, stderr=subprocess.PIPE, text=True,
                                     start_new_session=True)  # a Ctrl-C reaches the launcher only
        self.port = None
        self.stderr_lines = []
        self.seen_port = threading.Event()
        self.thread = threading.Thread(target=self._read_stderr, daemon=True)
        self.thread.start()

    def _read_stderr(self):
        with open(self.log_path, "w") as log:
            for line in self.proc.stderr:
                log.write(line)
                log.flush()
                self.stderr_lines.append(line)
                m = re.search(r"HTTP API on http://%s:(\d+)/" % re.escape(self.host), line)
                if m and self.port is None:
                    self.port = int(m.group(1))
                    self.seen_port.set()

    def wait_port(self, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.seen_port.wait(0.1):
                return self.port
            if self.proc.poll() is not None:
                break
        raise RuntimeError("%s gave no HTTP port (status %s):\n%s" % (self.name, self.proc.poll(),
                                                                    "".join(self.stderr_lines)))

    def values(self, refs):
        url = "http://%s:%d/api/v1/values?refs=%s" % (self.host, self.port, ",".join(refs))
        with urllib.request.urlopen(url, timeout=5) as r:
            return json.load(r)["values"]

    def stop(self):
        """SIGTERM, then SIGKILL after 10 s; returns what it printed on stdout."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.thread.join(5)
        self.out.close()
        with open(self.out_path) as f:
            return f.read()


class Namespaces:
    """--netns: a namespace per node, its veth on a bridge in the launcher's
    namespace (which has .254, to reach the nodes' HTTP APIs)."""

    def __init__(self, names):
        tag = os.getpid() % 10000
        self.net = "10.77.%d" % (os.getpid() % 250)
        self.bridge = "fadb%d" % tag
        self.ns = {n: "fad%d_%s" % (tag, n) for n in names}
        self.veth = {n: "fad%d%s" % (tag, n[0] + n[-1]) for n in names}  # the namespace's end (<= 15 chars)
        self.addr = {n: "%s.%d" % (self.net, i + 1) for i, n in enumerate(names)}
        self.made = []
        try:
            self._ip("link", "add", self.bridge, "type", "bridge")
            self.made.append(("link", self.bridge))
            self._ip("addr", "add", self.net + ".254/24", "dev", self.bridge)
            self._ip("link", "set", self.bridge, "up")
            for n in names:
                ns, veth, host_end = self.ns[n], self.veth[n], self.veth[n] + "h"
                self._ip("netns", "add", ns)
                self.made.append(("netns", ns))
                self._ip("link", "add", veth, "type", "veth", "peer", "name", host_end)
                self._ip("link", "set", veth, "netns", ns)
                self._ip("link", "set", host_end, "master", self.bridge, "up")
                self._ip("-n", ns, "addr", "add", self.addr[n] + "/24", "dev", veth)
                self._ip("-n", ns, "link", "set", veth, "up")
                self._ip("-n", ns, "link", "set", "lo", "up")
        except Exception:
            self.remove()
            raise

    @staticmethod
    def _ip(*args):
        r = subprocess.run(["ip"] + list(args), capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("ip %s: %s" % (" ".join(args), r.stderr.strip()))

    def sets(self, name):
        return ["net.interface=" + self.veth[name], "net.peers=[%s]" % ", ".join(self.addr.values())]

    def remove(self):
        for kind, what in reversed(self.made):  # a namespace takes its veth with it
            subprocess.run(["ip", kind, "del", what], capture_output=True)
        self.made = []


def dds_counters(stdout):
    """The dds driver's counters from `syncplc run`'s statistics at stop."""
    m = re.search(r"\(dds\)\n\s+(.*)", stdout)
    if not m:
        return {}
    out = {}
    for kv in m.group(1).split():
        k, _, v = kv.partition("=")
        try:
            out[k] = float(v) if "." in v else int(v)
        except ValueError:
            out[k] = v
    return out


def task_stats(stdout):
    m = re.search(r"^\s+servo\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)", stdout, re.M)
    return dict(zip(("scans", "overruns", "skipped", "watchdog_trips"), map(int, m.groups()))) if m else {}


def run(args):
    syncplc = os.path.join(args.build_dir, "syncplc")
    if not os.access(syncplc, os.X_OK):
        sys.exit("no syncplc in %s (--build-dir)" % args.build_dir)
    window = round(duration_s(args.duration) * 1000)
    domain = args.domain if args.domain is not None else 200 + os.getpid() % 30
    workdir = args.keep or tempfile.mkdtemp(prefix="four-axis-dds-")
    os.makedirs(workdir, exist_ok=True)
    # The window starts at master scan 100 and the nodes start within a few
    # seconds: the safety net of each process is far beyond both.
    limit_s = int(window / 1000 + 120)
    nodes = []
    spaces = None
    try:
        if args.netns:
            if os.geteuid() != 0:
                raise RuntimeError("--netns needs root (ip netns)")
            spaces = Namespaces(NODES)
        for name in NODES:
            sets = ["net.domain=%d" % domain] + (spaces.sets(name) if spaces else [])
            if name == "master":
                sets.append("window_scans=%d" % window)
            else:
                k = int(name[-1])
                if args.loss > 0:
                    sets += ["net.inject.loss=%g" % args.loss, "net.inject.seed=%d" % (args.seed + k)]
                if args.hold:
                    sets += ["n%d_%s.order=0" % (k, w) for w in "xva"]
            nodes.append(Node(syncplc, name, workdir, sets, limit_s, spaces.ns[name] if spaces else None,
                              spaces.addr[name] if spaces else "127.0.0.1"))
        for n in nodes:
            n.wait_port(60)
        master = nodes[-1]
        deadline = time.monotonic() + window / 1000 + 90
        while True:
            for n in nodes:
                if n.proc.poll() is not None:
                    raise RuntimeError("%s ended (status %d) before the window was complete:\n%s"
                                       % (n.name, n.proc.returncode, "".join(n.stderr_lines)))
            v = master.values(["window_done", "master_scan"])
            if v["window_done"]:
                break
            if time.monotonic() > deadline:
                raise RuntimeError("the master's window was not complete in time (scan %s)" % v["master_scan"])
            time.sleep(0.2)
        result = {"loss": args.loss, "estimator": "hold" if args.hold else "taylor", "domain": domain,
                  "network": "namespaces %s.0/24" % spaces.net if spaces else "loopback"}
        result.update(master.values(RESULTS))
        result["nodes"] = {}
        for n in nodes:
            if n is not master:
                result["nodes"][n.name] = n.values(["ref_lost", "ref_late", "following", "quick_stops"])
    finally:
        outs = {n.name: n.stop() for n in nodes}
        if spaces:
            spaces.remove()
        if not args.keep:
            shutil.rmtree(workdir, True)
    for name, out in outs.items():  # reached only when the window was read: an error went on from the finally
        node = result["nodes"].setdefault(name, {})
        proc = next(n.proc for n in nodes if n.name == name)
        node["pid"] = proc.pid
        node["exit"] = proc.returncode  # 0: stopped by SIGTERM as asked
        node["dds"] = dds_counters(out)
        node["task"] = task_stats(out)
    return result


def report(r):
    print("four-axis table on five DDS nodes: loss %g %%, %s" % (100 * r["loss"], r["estimator"]))
    print("  window: master scans %d .. %d (the cosine from scan %d): %d samples, %d skipped (not all four fresh)"
          % (r["window_from"], r["window_from"] + r["window_scans"] - 1, r["cos_start"], r["samples"], r["skipped"]))
    print("  Track-RSME %.6f rad   Sync-RSME %.6f rad" % (r["track_rsme"], r["sync_rsme"]))
    print("  max |e| per axis: %s rad" % " ".join("%.4f" % e for e in r["max_abs_e"]))
    print("  lag: max %d scans, %d samples above 2" % (r["lag_max"], r["lagged"]))
    print("  published reference vs the cosine: |dx| %.2e rad, |dv| %.2e rad/s, |da| %.2e rad/s^2" % tuple(r["ref_dev"]))
    for name, n in r["nodes"].items():
        d, t = n.get("dds", {}), n.get("task", {})
        print("  %-7s scans %s overruns %s | received %s lost %s late %s dropped_by_injection %s | phase p99 %s us%s"
              % (name, t.get("scans"), t.get("overruns"), d.get("samples_received"), d.get("samples_lost"),
                 d.get("samples_late"), d.get("samples_dropped_by_injection"), d.get("phase_abs_p99_us"),
                 " | quick stops %d" % n["quick_stops"] if "quick_stops" in n else ""))


def on_sigterm(signum, frame):
    # SIGTERM ends the launcher as Ctrl-C does: through the finally that stops the nodes.
    raise KeyboardInterrupt()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build-dir", default=os.path.join(ROOT, "build"))
    ap.add_argument("--loss", type=float, default=0.0, help="loss injected on every axis node's subscriptions, 0..1")
    ap.add_argument("--seed", type=int, default=1, help="injection seed (axis k: seed + k)")
    ap.add_argument("--hold", action="store_true", help="the estimators of ref hold (order 0)")
    ap.add_argument("--duration", default="6.283185s", help="the metrics window (master scans of 1 ms)")
    ap.add_argument("--domain", type=int, help="DDS domain (default: one of 200..229 from the pid)")
    ap.add_argument("--keep", help="keep the nodes' databases and logs in this directory")
    ap.add_argument("--json", action="store_true", help="print the result as JSON")
    ap.add_argument("--netns", action="store_true", help="each node in a network namespace of its own, on a bridge (root)")
    args = ap.parse_args()
    signal.signal(signal.SIGTERM, on_sigterm)
    try:
        r = run(args)
    except KeyboardInterrupt:
        sys.exit("four_axis_dds: interrupted; every node stopped")
    if args.json:
        print(json.dumps(r, indent=2))
    else:
        report(r)


if __name__ == "__main__":
    main()
