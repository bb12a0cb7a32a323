"""Who may do what, against two servers:

- `tests/peers/peers_denied.yaml` (allowed_clients without 127.0.0.1): every
  connection from 127.0.0.1 is accepted and closed at once (plain socket,
  pymodbus, mbpoll), no request is ever answered;
- `tests/peers/peers_read_only.yaml` (read_only: true, unit_id 17, allowed
  clients including 127.0.0.1, idle_timeout 0): every area reads, every write
  (FC 5, 6, 15, 16, 23; also to explicit places) is exception 02 and changes
  nothing, a bad coil value is still 03 (checked before the address), unit 1
  is now 0B while 0 and 255 are answered, and a silent connection is never
  closed for idleness.

    /usr/bin/python3 tests/peers/test_access.py build/syncplc
"""

import struct
import sys
import time

import peerlib as P
from test_exceptions import Raw, pdu_read, pdu_rw, pdu_write_coils, pdu_write_regs, pdu_write_single


check = P.check_true


def denied(binary):
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_denied.yaml"))
    try:
        for i in range(3):
            check(P.refused(server.port), "connection %d from 127.0.0.1 was not refused (allowed_clients)" % i)
            tally.refused += 1
        # A request sent at once gets no reply either.
        s = P.connect(server.port)
        try:
            s.sendall(P.mbap(1, 1, pdu_read(3, 1024, 1)))
        except OSError:
            pass
        check(P.closed_by_server(s), "a request from a refused client was answered")
        s.close()
        tally.refused += 1
        unanswered, r = P.pymodbus_unanswered(server.port)
        tally.refused += 1
        check(unanswered, "pymodbus from a refused address got %r" % (r,))
        m = P.run(["/usr/bin/mbpoll", "-p", str(server.port), "-1", "-0", "-o", "2", "-r", "1024", "127.0.0.1"],
                  timeout=60)
        tally.refused += 1
        check(m.returncode != 0 and "[1024]" not in m.stdout, "mbpoll from a refused address:\n" + m.stdout)
    finally:
        counters = server.stop()
    P.check_counters(counters, tally, label="allowed_clients without 127.0.0.1")


def read_only(binary):
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_read_only.yaml"))
    check(server.unit == 17, "the server says unit %s, the project 17" % server.unit)
    try:
        silent = P.connect(server.port)
        tally.connection()
        t_silent = time.monotonic()
        peer = P.Peer(server.port, tally, unit=17)
        r = Raw(server.port, tally)
        peer.wait_read("discrete", 0, 1, [True], "discrete input 0 after the first scan")
        reads = [("coil", 0, [False, False, True]), ("coil", 5000, [False]), ("discrete", 0, [True, False, False]),
                 ("input", 4, [0xFB2E, 0xBEEF, 0]), ("input", 3100, [42]), ("holding", 1024, [1000, 2000, 0x1234]),
                 ("holding", 3000, [0xFFFB, 200, 0xA5]),
                 ("holding", 2108, [0xFFFF, 0xFFFE, 0x1234, 0x5678, 0xDEAD, 0xBEEF, 0x3F80, 0])]
        for table, address, want in reads:
            got = peer.read(table, address, len(want))
            check(got == want, "read-only server: %s %d.. is %r, expected %r" % (table, address, got, want))
        check(P.decode(["LREAL"], peer.read("holding", 4228, 4)) == [1.5], "LREAL 1.5 on the read-only server")

        refused = [
            (pdu_write_single(5, 0, 0xFF00), "FC 5 to readwrite coil 0"),
            (pdu_write_single(5, 5000, 0x0000), "FC 5 to explicit readwrite coil 5000"),
            (pdu_write_coils(8, [1] * 10), "FC 15 to the BOOL array"),
            (pdu_write_single(6, 4, 1), "FC 6 to readwrite INT 4"),
            (pdu_write_single(6, 3000, 1), "FC 6 to explicit SINT 3000"),
            (pdu_write_regs(1028, [9, 9, 9, 9]), "FC 16 to the INT array"),
            (pdu_write_regs(2108, [0, 1, 0, 2, 0, 3, 0x4000, 0]), "FC 16 to DINT, UDINT, DWORD, REAL"),
            (pdu_write_regs(4216, [0] * 20), "FC 16 to every %ML"),
            (pdu_rw(1024, 3, 1024, [7, 7, 7]), "FC 23"),
            (pdu_write_regs(2114, [0x7FC0, 0]), "FC 16 of a NaN (02 before the value's 03)"),
            (pdu_write_single(6, 1074, 1), "FC 6 to the slow task's tag"),
        ]
        for pdu, what in refused:
            r.exc(pdu, 0x02, "read-only server: " + what, unit=17)
        peer.expect(0x02, "write_coil", 0, True, what="pymodbus FC 5 on a read-only server")
        peer.expect(0x02, "write_register", 1024, 5, what="pymodbus FC 6 on a read-only server")
        peer.expect(0x02, "write_registers", 4228, P.encode([("LREAL", 2.0)]), what="pymodbus FC 16 LREAL")
        peer.expect(0x02, "readwrite_registers", read_address=1034, read_count=1, write_address=1024,
                    write_registers=[5], what="pymodbus FC 23 on a read-only server")
        # Checks before the access check still come first.
        r.exc(pdu_write_single(5, 0, 0x1234), 0x03, "read-only server: FC 5 value 1234 (03 first)", unit=17)
        r.exc(pdu_write_regs(1028, [], quantity=0, byte_count=0), 0x03, "read-only server: FC 16 quantity 0", unit=17)
        r.exc(bytes([0x16, 0, 0, 0, 0, 0, 0]), 0x01, "read-only server: FC 22", unit=17)
        # Units: 17, 0 and 255 answered; 1 is another unit now.
        r.exc(pdu_read(3, 1024, 1), 0x0B, "unit 1 on a unit-17 server", unit=1)
        r.exc(pdu_write_single(6, 1024, 1), 0x0B, "a write to unit 1 on a unit-17 server", unit=1)
        for unit in (0, 255):
            check(r.ok(pdu_read(3, 1024, 1), "unit %d" % unit, unit=unit) == bytes([3, 2, 0x03, 0xE8]),
                  "unit %d read on the unit-17 server" % unit)
        r.exc(pdu_write_single(6, 1024, 1), 0x02, "FC 6 to unit 255 on a read-only server", unit=255)
        # mbpoll sees the same.
        m = P.run(["/usr/bin/mbpoll", "-p", str(server.port), "-1", "-0", "-o", "5", "-a", "17", "-t", "4", "-r", "1024",
                   "127.0.0.1", "5"], timeout=60)
        tally.connection()
        tally.exception(0x02)
        check(m.returncode != 0 and "Illegal data address" in m.stdout, "mbpoll write on a read-only server:\n" + m.stdout)
        m = P.run(["/usr/bin/mbpoll", "-p", str(server.port), "-1", "-0", "-o", "5", "-a", "17", "-t", "4", "-c", "3",
                   "-r", "1024", "127.0.0.1"], timeout=60)
        tally.connection()
        tally.ok()
        check(m.returncode == 0 and "[1024]: \t1000" in m.stdout, "mbpoll read on a read-only server:\n" + m.stdout)

        # Nothing changed, after a few scans.
        time.sleep(0.1)
        for table, address, want in reads:
            got = peer.read(table, address, len(want))
            check(got == want, "after the refused writes %s %d.. is %r, expected %r" % (table, address, got, want))
        # idle_timeout 0: the silent connection is still open (well past a second).
        while time.monotonic() - t_silent < 1.5:
            time.sleep(0.05)
        check(not P.readable_soon(silent, 0.1), "a silent connection was closed with idle_timeout 0")
        P.transact(silent, P.mbap(1, 17, pdu_read(3, 1024, 1)))
        tally.ok()
        silent.close()
        peer.close()
        r.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally, label="read_only, unit 17")


def main():
    binary = P.syncplc_binary()
    denied(binary)
    read_only(binary)
    print("test_access: OK")


if __name__ == "__main__":
    sys.exit(main())
