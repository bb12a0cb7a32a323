"""Two nodes over DDS, each its own `syncplc run` (docs/dds.md): node A
counts its scans and publishes the count; node B subscribes to it
(stale_after 20 scans, reaction safe) and serves what it sees on its Modbus
server, read here with pymodbus. A third node that gives the topic another
size is refused at start with a message that names both. A is killed with SIGKILL: B sees the
subscription stale and takes the safe value; A is started again: B takes its
samples again without a restart, though A's scans count from 0 once more.
Loopback only, unicast discovery (multicast off), a domain of this test's own.

  /usr/bin/python3 tests/peers/test_dds_nodes.py build/syncplc
"""
import atexit
import os
import shutil
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402

DOMAIN = 100 + os.getpid() % 100
TOPIC = "count_%d" % os.getpid()

NODE_A = """
project: {{name: dds_a, version: 1.0.0}}
tasks: [{{name: main, period: 5ms}}]
tags:
  - {{name: count, type: LREAL}}
blocks:
  - {{name: inc, type: ADD, datatype: LREAL, inputs: {{IN2: 1.0}}}}
  - {{name: last, type: UNIT_DELAY}}
connections:
  - last.OUT -> inc.IN1
  - inc.OUT -> last.IN
  - inc.OUT -> count
drivers:
  - name: net
    type: dds
    node: a
    domain: {domain}
    peers: [127.0.0.1]
    interface: 127.0.0.1
    publish: [{{topic: {topic}, values: 1}}]
    bind: {{{topic}: count}}
modbus: {{}}
"""

NODE_B = """
project: {{name: dds_b, version: 1.0.0}}
tasks: [{{name: main, period: 5ms}}]
tags:
  - {{name: x, type: LREAL, hmi: read, modbus: {{table: input_register, address: 0}}}}
  - {{name: x_age, type: UDINT, hmi: read, modbus: {{table: input_register, address: 4}}}}
  - {{name: x_ok, type: BOOL, hmi: read, modbus: {{table: discrete_input, address: 0}}}}
  - {{name: x_reaction, type: BOOL, hmi: read, modbus: {{table: discrete_input, address: 1}}}}
drivers:
  - name: net
    type: dds
    node: b
    domain: {domain}
    peers: [127.0.0.1]
    interface: 127.0.0.1
    subscribe: [{{topic: {topic}, values: 1, stale_after: 20, reaction: safe, safe: -1}}]
    bind: {{{topic}: x, {topic}_age: x_age, {topic}_ok: x_ok, {topic}_reaction: x_reaction}}
modbus: {{}}
"""

# A node that takes the topic as two values: refused at start.
NODE_C = """
project: {{name: dds_c, version: 1.0.0}}
tasks: [{{name: main, period: 5ms}}]
tags:
  - {{name: y, type: "ARRAY[1..2] OF LREAL"}}
drivers:
  - name: net
    type: dds
    node: c
    domain: {domain}
    peers: [127.0.0.1]
    interface: 127.0.0.1
    subscribe: [{{topic: {topic}, values: 2}}]
    bind: {{{topic}: y}}
"""


def b_view(hmi):
    """What node B serves on its Modbus server, through `hmi`: seen() gives
    (x, x_ok, x_reaction); until(pred, what) polls it until pred holds (a 30 s
    guard against a hang) and returns that view."""
    def seen():
        x = hmi.read_values(0, ["LREAL"], table="input")[0]
        ok, reaction = hmi.read("discrete", 0, 2)
        return x, ok, reaction

    def until(pred, what):
        return peerlib.wait_until(lambda: (lambda v: (pred(v), v))(seen()), what, timeout=30)[0]

    return seen, until


def write(tmp, name, text):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(text.format(domain=DOMAIN, topic=TOPIC))
    return path


def main():
    binary = peerlib.syncplc_binary()
    tmp = tempfile.mkdtemp(prefix="dds-nodes-")
    atexit.register(shutil.rmtree, tmp, True)
    path_a, path_b = write(tmp, "a.yaml", NODE_A), write(tmp, "b.yaml", NODE_B)
    b = peerlib.Server(binary, path_b, extra=("--db", os.path.join(tmp, "b.db")))
    a = peerlib.Server(binary, path_a, extra=("--db", os.path.join(tmp, "a.db")))
    hmi = peerlib.Peer(b.port, peerlib.Tally())
    seen, until = b_view(hmi)

    # A's count reaches B and grows.
    until(lambda v: v[1] and v[0] > 10, "B sees A's count")
    until(lambda v: v[0] > 400, "the count B sees grows")

    # A third node whose project gives the topic two values is refused at start, with both sizes named.
    path_c = write(tmp, "c.yaml", NODE_C)
    c = peerlib.run([binary, "run", path_c, "--no-status", "--modbus-port", "0", "-d", "20s",
                     "--db", os.path.join(tmp, "c.db")], timeout=60)
    peerlib.check_true(c.returncode != 0, "the mismatched node did not start (status %d)" % c.returncode)
    want = "topic %s: node 'a' publishes 1 value, this node takes 2: the nodes' projects do not match" % TOPIC
    peerlib.check_true(want in c.stdout, "its message names the topic and both sizes:\n" + c.stdout)

    # SIGKILL: no goodbye on the wire. B goes stale after 20 of its scans and
    # takes the safe value.
    a.proc.send_signal(signal.SIGKILL)
    a.proc.wait(timeout=30)
    killed = time.monotonic()
    until(lambda v: not v[1], "B sees A's samples stop")
    stale_after_s = time.monotonic() - killed
    until(lambda v: v[2] and v[0] == -1.0, "B reacts: the safe value")
    print("B saw A stale %.0f ms after SIGKILL (stale_after 20 scans of 5 ms = 100 ms)" % (1000 * stale_after_s))

    # A again: its scans count from 1 again, and B takes them without a restart.
    a2 = peerlib.Server(binary, path_a, extra=("--db", os.path.join(tmp, "a2.db")))
    x2 = until(lambda v: v[1] and 0 < v[0] < 300, "B takes the restarted A's samples")[0]
    until(lambda v: v[0] > x2 + 20, "and its count grows")
    peerlib.check_true(not seen()[2], "B's reaction ends with the samples")

    hmi.close()
    a2.stop()
    b.stop()
    print("dds nodes: OK")


if __name__ == "__main__":
    main()
