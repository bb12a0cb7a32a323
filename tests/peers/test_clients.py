"""64 clients at once against `syncplc run tests/peers/peers.yaml` (max_clients
64, the default): 64 threads, each with its own pymodbus connection, all
connected together, all served, also while they hammer the server at the same
time; the 65th connection is accepted and closed at once (refused), both for
a plain socket and for pymodbus; once one of the 64 leaves, a new client gets
in. The server's counters must match at the end.

    /usr/bin/python3 tests/peers/test_clients.py build/syncplc
"""

import sys
import threading
import time

import peerlib as P

CLIENTS = 64
ROUNDS = 25


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers.yaml"))
    errors = []
    try:
        first = P.Peer(server.port, tally)
        first.wait_read("discrete", 0, 1, [True], "discrete input 0 after the first scan")
        first.close()
        peers_all = [P.Peer(server.port, tally, timeout=10) for _ in range(CLIENTS)]

        barrier = threading.Barrier(CLIENTS)

        def work(k, peer, rounds, write):
            try:
                barrier.wait(timeout=60)
                for n in range(rounds):
                    v = peer.read("holding", 1024, 3)
                    if v[2] != 0x1234:
                        raise AssertionError("client %d: holding 1026 is %r" % (k, v[2]))
                    bits = peer.read("discrete", 0, 3)
                    if bits[0] is not True:
                        raise AssertionError("client %d: discrete input 0 is %r" % (k, bits[0]))
                    vals = peer.read_values(2108, ["DINT", "UDINT", "DWORD", "REAL"])
                    if vals[1] != 0x12345678:
                        raise AssertionError("client %d: UDINT is %r" % (k, vals[1]))
                if write:
                    peer.write_register(1028 + k % 4, k)
            except Exception as e:  # noqa: BLE001  reported by the main thread
                errors.append("client %d: %s" % (k, e))

        def all_clients(rounds, write):
            threads = [threading.Thread(target=work, args=(k, p, rounds, write)) for k, p in enumerate(peers_all)]
            t0 = time.monotonic()
            for t in threads:
                t.start()
            for t in threads:
                t.join(timeout=120)
            if errors:
                raise AssertionError("%d of %d clients failed:\n  %s" % (len(errors), CLIENTS, "\n  ".join(errors[:10])))
            return time.monotonic() - t0

        elapsed = all_clients(ROUNDS, True)
        print("%d clients x %d rounds of 3 reads + 1 write: %.2f s" % (CLIENTS, ROUNDS, elapsed))

        # The 65th: accepted by the kernel, closed by the server before any request.
        if not P.refused(server.port):
            raise AssertionError("a 65th connection was not closed at once (max_clients 64)")
        tally.refused += 1
        late = P.pymodbus_client(server.port, timeout=2)
        try:
            r = late.read_holding_registers(1024, 1, slave=1)
        except Exception as e:  # noqa: BLE001  pymodbus raises or returns an error, by version
            r = e
        late.close()
        tally.refused += 1
        if not (isinstance(r, Exception) or r.isError()) or hasattr(r, "exception_code"):
            raise AssertionError("pymodbus as the 65th client got %r, expected no response" % (r,))
        print("pymodbus as the 65th client: %r" % (r,))

        # The 64 are still served.
        all_clients(2, False)

        # One leaves: a new client gets in (once the server has seen the close).
        peers_all[0].close()
        deadline = time.monotonic() + 10
        while True:
            s = P.connect(server.port)
            try:
                reply = None
                try:
                    reply = P.transact(s, P.mbap(1, 1, bytes([3, 0x04, 0x00, 0, 1])))
                except (AssertionError, ConnectionError):
                    pass
                if reply is not None:
                    if reply != bytes([3, 2, 0x03, 0xE8]):
                        raise AssertionError("the new client got %s" % reply.hex(" "))
                    tally.connection()
                    tally.ok()
                    break
                tally.refused += 1
            finally:
                s.close()
            if time.monotonic() > deadline:
                raise AssertionError("no new client got in within 10 s after one of 64 left")
            time.sleep(0.02)
        for p in peers_all[1:]:
            p.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_clients: OK")


if __name__ == "__main__":
    sys.exit(main())
