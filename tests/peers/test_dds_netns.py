"""Two nodes over DDS across network namespaces (docs/dds.md): node A runs
in a network namespace this test makes, joined to the test's own namespace
by a veth pair with addresses of a /30 of its own; node B runs here. Each
names the other's address as its only peer (unicast discovery, multicast
off) and its end of the veth as its interface. A's count reaches B; A's
namespace loses its link (the veth is taken down): B sees A stale and takes
the safe value; the link comes back: B takes A's samples again. Needs root
(ip netns); skipped (77) without it. Everything it made is removed at exit.

  /usr/bin/python3 tests/peers/test_dds_netns.py build/syncplc
"""
import atexit
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402
from test_dds_nodes import NODE_A, NODE_B, b_view  # noqa: E402

PID = os.getpid()
NS = "sdds%d" % PID
VETH_HERE, VETH_THERE = "sdh%d" % (PID % 100000), "sdt%d" % (PID % 100000)
NET = "10.251.%d" % (PID % 250)
ADDR_HERE, ADDR_THERE = NET + ".1", NET + ".2"
DOMAIN = 100 + PID % 100
TOPIC = "count_%d" % PID


def ip(*args, check=True):
    return subprocess.run(["ip", *args], check=check, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def cleanup():
    ip("link", "del", VETH_HERE, check=False)
    ip("netns", "del", NS, check=False)


def node(text, me, peer):
    return (text.replace("peers: [127.0.0.1]", "peers: [%s]" % peer)
                .replace("interface: 127.0.0.1", "interface: %s" % me)
                .format(domain=DOMAIN, topic=TOPIC))


def main():
    if os.geteuid() != 0 or shutil.which("ip") is None:
        print("skipped: needs root and ip(8) to make a network namespace")
        sys.exit(77)
    atexit.register(cleanup)
    if ip("netns", "add", NS, check=False).returncode != 0:
        print("skipped: this machine does not let the test make a network namespace")
        sys.exit(77)
    ip("link", "add", VETH_HERE, "type", "veth", "peer", "name", VETH_THERE)
    ip("link", "set", VETH_THERE, "netns", NS)
    ip("addr", "add", ADDR_HERE + "/30", "dev", VETH_HERE)
    ip("link", "set", VETH_HERE, "up")
    ip("-n", NS, "addr", "add", ADDR_THERE + "/30", "dev", VETH_THERE)
    ip("-n", NS, "link", "set", VETH_THERE, "up")
    ip("-n", NS, "link", "set", "lo", "up")

    binary = peerlib.syncplc_binary()
    tmp = tempfile.mkdtemp(prefix="dds-netns-")
    atexit.register(shutil.rmtree, tmp, True)
    path_a, path_b = os.path.join(tmp, "a.yaml"), os.path.join(tmp, "b.yaml")
    with open(path_a, "w") as f:
        f.write(node(NODE_A, ADDR_THERE, ADDR_HERE))
    with open(path_b, "w") as f:
        f.write(node(NODE_B, ADDR_HERE, ADDR_THERE))
    b = peerlib.Server(binary, path_b, extra=("--db", os.path.join(tmp, "b.db")))
    # A in the namespace (its Modbus server on the namespace's own loopback, unused).
    a_proc = subprocess.Popen(["ip", "netns", "exec", NS, binary, "run", path_a, "--no-status", "--modbus-port", "0",
                               "-d", "120s", "--db", os.path.join(tmp, "a.db")],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    atexit.register(lambda: a_proc.poll() is None and a_proc.kill())
    hmi = peerlib.Peer(b.port, peerlib.Tally())
    _, until = b_view(hmi)

    until(lambda v: v[1] and v[0] > 10, "B sees the count of A in the other namespace")
    x = until(lambda v: v[0] > 100, "and it grows")[0]
    ip("-n", NS, "link", "set", VETH_THERE, "down")
    until(lambda v: not v[1] and v[2] and v[0] == -1.0, "B sees A stale once the link is down, and takes the safe value")
    ip("-n", NS, "link", "set", VETH_THERE, "up")
    until(lambda v: v[1] and v[0] > x, "B takes A's samples again once the link is back")

    hmi.close()
    a_proc.terminate()
    out, _ = a_proc.communicate(timeout=60)
    peerlib.check_true(a_proc.returncode == 0, "node A stopped cleanly:\n" + out)
    b.stop()
    print("dds across network namespaces: OK")


if __name__ == "__main__":
    main()
