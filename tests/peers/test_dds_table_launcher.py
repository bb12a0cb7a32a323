"""scripts/four_axis_dds.py (docs/four-axis-dds.md) for half a second of
window at 20 % injected loss: it starts the five nodes, reads the master's
results over HTTP once the window is complete, prints them as JSON with
every node's DDS counters, and leaves no process behind.

  /usr/bin/python3 tests/peers/test_dds_table_launcher.py build/syncplc
  /usr/bin/python3 tests/peers/test_dds_table_launcher.py build/syncplc --netns

--netns: each node in a network namespace of its own, their veths on a
bridge the launcher makes (root only; skipped, status 77, without it); the
namespaces and the bridge are gone afterwards.
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: /usr/bin/python3 %s PATH/TO/syncplc" % sys.argv[0])
    build = os.path.dirname(os.path.abspath(sys.argv[1]))
    netns = "--netns" in sys.argv[2:]
    if netns and (os.geteuid() != 0 or subprocess.run(["ip", "netns", "list"], capture_output=True).returncode != 0):
        print("skipped: --netns needs root and ip netns")
        sys.exit(77)
    domain = 170 + os.getpid() % 30
    out = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "four_axis_dds.py"), "--build-dir", build,
                          "--duration", "0.5s", "--loss", "0.2", "--seed", "3", "--domain", str(domain), "--json"]
                         + (["--netns"] if netns else []),
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=240)
    check(out.returncode == 0, "the launcher failed:\n" + out.stdout)
    r = json.loads(out.stdout)
    print("Track-RSME %.4f, Sync-RSME %.4f, %d samples, %d skipped"
          % (r["track_rsme"], r["sync_rsme"], r["samples"], r["skipped"]))
    check(r["window_scans"] == 500 and r["samples"] + r["skipped"] == 500, "a window of 500 scans, each counted: %r" % r)
    check(r["samples"] > 0 and 0 < r["track_rsme"] < 1 and 0 < r["sync_rsme"] < 1, "errors measured: %r" % r)
    check(r["domain"] == domain and r["loss"] == 0.2 and r["estimator"] == "taylor", "the options taken: %r" % r)
    check(r["network"].startswith("namespaces") if netns else r["network"] == "loopback", "the network: %r" % r)
    if netns:
        left = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True).stdout
        links = subprocess.run(["ip", "-o", "link"], capture_output=True, text=True).stdout
        check(r["network"].split()[1].startswith("10.77."), "the launcher's subnet: %r" % r["network"])
        check("fad" not in left and "fadb" not in links, "namespaces and bridge removed:\n%s%s" % (left, links))
    check(sorted(r["nodes"]) == ["axis1", "axis2", "axis3", "axis4", "master"], "five nodes: %r" % sorted(r["nodes"]))
    for name, n in r["nodes"].items():
        dds = n["dds"]
        check(dds.get("samples_sent", 0) > 500 and dds.get("samples_received", 0) > 500,
              "%s exchanged samples: %r" % (name, dds))
        injected = dds.get("samples_dropped_by_injection", -1)
        check(injected == 0 if name == "master" else injected > 0, "%s: loss injected on the axes only: %r" % (name, dds))
        check(n["exit"] == 0, "%s ended with status %r, not as SIGTERM asks (a sanitizer report?)" % (name, n["exit"]))
        check(n["task"].get("scans", 0) > 500, "%s: its task statistics: %r" % (name, n["task"]))
        check(name == "master" or n["quick_stops"] == 0, "%s followed the master throughout: %r" % (name, n))
        # Stopped and reaped: the pid names no process of ours any more.
        try:
            os.kill(n["pid"], 0)
            alive = open("/proc/%d/cmdline" % n["pid"]).read().find("four_axis_dds") >= 0
        except (ProcessLookupError, FileNotFoundError):
            alive = False
        check(not alive, "%s (pid %d) was stopped" % (name, n["pid"]))
    print("dds table launcher: OK")


if __name__ == "__main__":
    main()
