"""Online change (SIGHUP) under Modbus traffic: `syncplc run tests/peers/peers_online.yaml`
with a 2 s task, so that its writes are still queued when the program is
replaced. A write acknowledged before the change must not be lost with the
old program: pymodbus writes slow_a := 77 (FC 6), then a raw client sends a
write and read (FC 23: slow_b := 9, read slow_a..slow_b) and a read (FC 3)
pipelined behind it; both wait for the slow task. At SIGHUP the server takes
the new program at once while the old tasks go on until their switch: the
old slow task applies the queued writes at its next scan and mirrors it into
the new program, so the FC 23 is answered from the new program (77, 9) two
slow publications later, the FC 3 behind it too, and the connection stays
open throughout. The counters must match at the end. Counted in the slow
task's scans (its status registers, input registers 9000-9007: scans at
9002-9005), not in seconds.

    /usr/bin/python3 tests/peers/test_online_change.py build/syncplc
"""

import signal
import sys
import time

import peerlib as P

WRITE_READ = bytes([0x17, 0x04, 0x00, 0, 2, 0x04, 0x01, 0, 1, 2, 0, 9])  # write 1025 := 9, read 1024..1025
READ = bytes([0x03, 0x04, 0x00, 0, 2])


def slow_scans(peer):
    """The slow task's scan count (task 0's status block, docs/modbus.md)."""
    r = peer.read("input", 9000, 8)
    return (r[2] << 48) | (r[3] << 32) | (r[4] << 16) | r[5]


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_online.yaml"))
    try:
        peer = P.Peer(server.port, tally)
        P.check_equal(peer.read("holding", 1024, 2), [5, 6], "initial values")
        # Once the slow task's first scan has passed, its next one is about 2 s away.
        P.wait_until(lambda: (slow_scans(peer) >= 1, None), "the slow task's first scan")
        before = slow_scans(peer)
        peer.write_register(1024, 77)
        P.check_equal(peer.read("holding", 1024, 2), [5, 6], "the write waits for the slow task's next scan")

        s = P.connect(server.port, timeout=20)
        tally.connection()
        s.sendall(P.mbap(1, 1, WRITE_READ) + P.mbap(2, 1, READ))
        time.sleep(0.2)
        if P.readable_soon(s, 0):
            raise AssertionError("the write and read was answered before the slow task ran")

        server.proc.send_signal(signal.SIGHUP)
        t0 = time.monotonic()
        replies = [P.recv_reply(s), P.recv_reply(s)]
        elapsed = time.monotonic() - t0
        P.check_equal(replies[0], (1, 1, bytes([0x17, 4, 0, 77, 0, 9])), "FC 23 across the online change")
        P.check_equal(replies[1], (2, 1, bytes([0x03, 4, 0, 77, 0, 9])), "FC 3 pipelined behind it")
        tally.ok(2, written=1)
        print("FC 23 and the read behind it answered %.2f s after SIGHUP" % elapsed)
        scans = slow_scans(peer) - before
        print("  the slow task scanned %d times meanwhile" % scans)
        if scans > 2:
            raise AssertionError("the write and read waited %d slow scans: more than two" % scans)
        P.wait_until(lambda: (any("reloaded" in l for l in server.stderr_lines), None), "the reload message")
        P.check_equal(peer.read("holding", 1024, 2), [77, 9], "after the change: no acknowledged write lost")
        P.check_equal(peer.read("holding", 2068, 2), [0, 0], "fast_x (%MD10), the other task's tag")
        s.close()
        peer.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_online_change: OK")


if __name__ == "__main__":
    sys.exit(main())
