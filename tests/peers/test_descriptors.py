"""More clients than select() can watch: `syncplc run tests/peers/peers_many.yaml`
(max_clients 1200) with 1150 connections open at once, so the server's
descriptors for them run past 1024, where an fd_set stops (libmodbus 3.1.6's
modbus_receive and its examples use select(); docs/modbus.md, how it is
built). The script checks from /proc that the server really holds
descriptors >= 1024, then sends a request on every connection before it
reads any reply (1150 requests in flight), twice, in both orders, with one
more connection holding half a frame the whole time. Every reply must be
right, and the server's counters must match at the end. Under a hard limit
too low for max_clients, the server must say so when it starts.

    /usr/bin/python3 tests/peers/test_descriptors.py build/syncplc
"""

import os
import resource
import subprocess
import sys

import peerlib as P

CLIENTS = 1150
READ = bytes([3, 0x04, 0x00, 0, 3])             # FC 3, holding registers 1024..1026
ANSWER = bytes([3, 6, 0x03, 0xE8, 0x07, 0xD0, 0x12, 0x34])  # 1000, 2000, 0x1234 (peers_common.yaml)


def raise_own_limit(want):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if soft < want:
        if hard != resource.RLIM_INFINITY and hard < want:
            raise AssertionError("this machine allows %d descriptors a process; the test needs %d" % (hard, want))
        resource.setrlimit(resource.RLIMIT_NOFILE, (want, hard))


def server_descriptors(pid):
    return sorted(int(fd) for fd in os.listdir("/proc/%d/fd" % pid))


def too_few_descriptors(binary):
    """Under a hard limit of 512 descriptors the server says that 1200 clients will not fit."""
    def limit():
        resource.setrlimit(resource.RLIMIT_NOFILE, (512, 512))
    r = subprocess.run([binary, "run", P.project("peers_many.yaml"), "--no-status", "--modbus-port", "0", "-d", "200ms"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=limit, timeout=60)
    want = ("syncplc: modbus: warning: max_clients 1200 needs 1456 descriptors, this process may open only 512 "
            "(raise the hard limit: ulimit -Hn, LimitNOFILE=)")
    if r.returncode != 0 or want not in r.stderr:
        raise AssertionError("under a 512-descriptor limit: status %d, expected on stderr\n  %s\ngot\n%s"
                             % (r.returncode, want, r.stderr))
    print("under a 512-descriptor limit: warned")


def main():
    binary = P.syncplc_binary()
    too_few_descriptors(binary)
    raise_own_limit(CLIENTS + 256)
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_many.yaml"))
    socks = []
    stalled = None
    try:
        stalled = P.connect(server.port)
        tally.connection()
        stalled.sendall(P.mbap(1, 1, READ)[:9])  # half a frame, never finished
        for _ in range(CLIENTS):
            socks.append(P.connect(server.port, timeout=30))
        tally.connection(CLIENTS)

        def round_trip(order, tid):
            for k in order:
                socks[k].sendall(P.mbap((tid + k) & 0xFFFF, 1, READ))
            for k in order:
                t, unit, pdu = P.recv_reply(socks[k])
                if (t, unit, pdu) != ((tid + k) & 0xFFFF, 1, ANSWER):
                    raise AssertionError("connection %d: reply tid %d unit %d %s, expected tid %d unit 1 %s"
                                         % (k, t, unit, pdu.hex(" "), (tid + k) & 0xFFFF, ANSWER.hex(" ")))
            tally.ok(len(order))

        round_trip(range(CLIENTS), 1)
        fds = server_descriptors(server.proc.pid)
        above = [fd for fd in fds if fd >= 1024]
        print("server holds %d descriptors, %d of them >= 1024 (highest %d)" % (len(fds), len(above), fds[-1]))
        if len(above) < 100:
            raise AssertionError("the server holds only %d descriptors >= 1024: the test does not reach "
                                 "past an fd_set" % len(above))
        round_trip(range(CLIENTS - 1, -1, -1), 30001)
        # The half frame is still waiting, and costs nobody anything: finish it now.
        stalled.sendall(P.mbap(1, 1, READ)[9:])
        if P.recv_reply(stalled) != (1, 1, ANSWER):
            raise AssertionError("the stalled connection's request, once finished, was not answered")
        tally.ok()
        print("%d connections, 2 x %d requests in flight at once: all answered" % (CLIENTS + 1, CLIENTS))
    finally:
        for s in socks:
            s.close()
        counters = server.stop()
        if stalled:
            stalled.close()
    P.check_counters(counters, tally)
    print("test_descriptors: OK")


if __name__ == "__main__":
    sys.exit(main())
