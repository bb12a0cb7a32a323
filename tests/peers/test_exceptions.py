"""Every exception the server gives, and every frame it refuses, against
`syncplc run tests/peers/peers.yaml` (server defaults):

  01  unknown function codes (pymodbus FC 7, 8, 22; raw 0, 0x2B, 0x99)
  03  bad quantity (0, over the limit), PDU length, byte count; written values
      outside the tag's type (non-finite REAL/LREAL, coil value not FF00/0000)
  02  unmapped addresses, ranges that cut a 32/64-bit value or run past 65535,
      writes to read-only tags
  06  the write queue of a slow task (16 entries, one scan every 10 s) full
  0B  a unit id other than 1, 0 and 255
  and the checks' order (01 before 03 before 02 before a value's 03; the unit first).

Frames that are not Modbus TCP (protocol id not 0, length field outside 2..254,
an HTTP request) close the connection without a reply; random PDUs in good
frames get a well-formed reply each; clients that vanish mid-frame (FIN or
reset, also with an FC 23 pending) cost nothing. A refused request changes no
value. The server's counters must match at the end.

    /usr/bin/python3 tests/peers/test_exceptions.py build/syncplc
"""

import random
import socket
import struct
import sys
import time

import peerlib as P

ILLEGAL_FUNCTION, ILLEGAL_ADDRESS, ILLEGAL_VALUE, BUSY, GATEWAY_TARGET = 0x01, 0x02, 0x03, 0x06, 0x0B


def pdu_read(fc, address, quantity):
    return struct.pack(">BHH", fc, address, quantity)


def pdu_write_single(fc, address, value):
    return struct.pack(">BHH", fc, address, value)


def pdu_write_coils(address, bits, quantity=None, byte_count=None, extra=b""):
    data = bytearray((len(bits) + 7) // 8)
    for i, b in enumerate(bits):
        if b:
            data[i // 8] |= 1 << (i % 8)
    q = len(bits) if quantity is None else quantity
    n = len(data) if byte_count is None else byte_count
    return struct.pack(">BHHB", 0x0F, address, q, n) + bytes(data) + extra


def pdu_write_regs(address, regs, quantity=None, byte_count=None, extra=b""):
    q = len(regs) if quantity is None else quantity
    n = 2 * len(regs) if byte_count is None else byte_count
    return struct.pack(">BHHB", 0x10, address, q, n) + b"".join(struct.pack(">H", r) for r in regs) + extra


def pdu_rw(read_address, read_quantity, write_address, regs, write_quantity=None, byte_count=None):
    q = len(regs) if write_quantity is None else write_quantity
    n = 2 * len(regs) if byte_count is None else byte_count
    return (struct.pack(">BHHHHB", 0x17, read_address, read_quantity, write_address, q, n)
            + b"".join(struct.pack(">H", r) for r in regs))


class Raw:
    """A plain-socket client that counts into the tally."""

    def __init__(self, port, tally):
        self.s = P.connect(port)
        self.tally = tally
        self.tid = 0
        tally.connection()

    def frame(self, pdu, unit=1):
        self.tid = (self.tid + 1) & 0xFFFF
        return P.mbap(self.tid, unit, pdu)

    def exc(self, pdu, code, what, unit=1):
        P.raw_exception(self.s, self.frame(pdu, unit), code, what)
        self.tally.exception(code)

    def ok(self, pdu, what, unit=1, written=0):
        reply = P.transact(self.s, self.frame(pdu, unit))
        if reply[0] != pdu[0]:
            raise AssertionError("%s: expected a normal reply to FC %d, got %s" % (what, pdu[0], reply.hex(" ")))
        self.tally.ok(written=written)
        return reply

    def any(self, pdu, unit=1):
        """Sends; returns the reply, counted as whatever it is."""
        frame = self.frame(pdu, unit)
        reply = P.transact(self.s, frame)
        if reply[0] == pdu[0] | 0x80 and len(reply) == 2:
            self.tally.exception(reply[1])
        elif reply[0] == pdu[0]:
            self.tally.ok()
        else:
            raise AssertionError("reply %s to %s" % (reply.hex(" "), frame.hex(" ")))
        return reply

    def close(self):
        self.s.close()


def busy(port, tally):
    """06: fill the write queue of task slow (16 entries, a scan every 10 s)."""
    r = Raw(port, tally)
    taken = 0
    for i in range(200):
        reply = P.transact(r.s, r.frame(pdu_write_single(6, 1074, i)))
        if reply == bytes([0x86, BUSY]):
            tally.exception(BUSY)
            break
        if reply[0] != 6:
            raise AssertionError("FC 6 to slow_set: reply %s" % reply.hex(" "))
        tally.ok(written=1)
        taken += 1
    else:
        raise AssertionError("200 writes to the slow task's tag (write_queue 16) never got exception 06")
    if taken < 15:
        raise AssertionError("the queue of 16 took only %d writes before exception 06" % taken)
    # Still full: every kind of write to that task is busy, FC 23 too (before it waits for a scan).
    r.exc(pdu_write_single(6, 1074, 1), BUSY, "FC 6 to a full queue")
    r.exc(pdu_write_regs(1074, [1]), BUSY, "FC 16 to a full queue")
    r.exc(pdu_rw(1024, 1, 1074, [1]), BUSY, "FC 23 to a full queue")
    # Reads of that task and writes to the other task's tags are unaffected.
    r.ok(pdu_read(3, 1074, 1), "read slow_set while its queue is full")
    r.ok(pdu_write_single(6, 1024, 77), "FC 6 to task main while slow's queue is full", written=1)
    print("busy: the slow task's queue took %d writes, then exception 06" % taken)
    r.close()


def illegal_function(peer, r):
    peer.expect(ILLEGAL_FUNCTION, "read_exception_status", what="FC 7 (read exception status)")
    peer.expect(ILLEGAL_FUNCTION, "diag_read_bus_message_count", what="FC 8 (diagnostics)")
    peer.expect(ILLEGAL_FUNCTION, "mask_write_register", address=1024, and_mask=0xFFFF, or_mask=0,
                what="FC 22 (mask write register)")
    for fc in (0x00, 0x07, 0x14, 0x18, 0x2B, 0x41, 0x7F, 0x99, 0xFF):
        r.exc(bytes([fc]) + b"\x00\x00\x00\x01", ILLEGAL_FUNCTION, "FC %02X" % fc)
    r.exc(bytes([0x2B]), ILLEGAL_FUNCTION, "FC 2B without data (length field 2)")
    # 01 comes before 03 and 02: an unknown FC with a nonsense body.
    r.exc(bytes([0x42]) + b"\xff" * 40, ILLEGAL_FUNCTION, "FC 42 with 40 bytes")


def illegal_value(peer, r):
    limits = {1: 2000, 2: 2000, 3: 125, 4: 125}
    for fc, limit in limits.items():
        r.exc(pdu_read(fc, 0, 0), ILLEGAL_VALUE, "FC %d quantity 0" % fc)
        r.exc(pdu_read(fc, 0, limit + 1), ILLEGAL_VALUE, "FC %d quantity %d" % (fc, limit + 1))
        r.exc(pdu_read(fc, 0, 0xFFFF), ILLEGAL_VALUE, "FC %d quantity 65535" % fc)
        r.exc(pdu_read(fc, 8, 1)[:4], ILLEGAL_VALUE, "FC %d with a PDU one byte short" % fc)
        r.exc(pdu_read(fc, 8, 1) + b"\x00", ILLEGAL_VALUE, "FC %d with a PDU one byte long" % fc)
        r.exc(bytes([fc]), ILLEGAL_VALUE, "FC %d without data (length field 2)" % fc)
    # pymodbus sends quantity 0 as it is told to.
    peer.expect(ILLEGAL_VALUE, "read_holding_registers", 1024, 0, what="pymodbus FC 3 count 0")
    peer.expect(ILLEGAL_VALUE, "read_coils", 0, 2001, what="pymodbus FC 1 count 2001")
    # 03 (quantity) before 02 (address): a bad quantity at an unmapped address.
    r.exc(pdu_read(3, 60000, 0), ILLEGAL_VALUE, "FC 3 quantity 0 at unmapped 60000")
    r.exc(pdu_read(3, 60000, 126), ILLEGAL_VALUE, "FC 3 quantity 126 at unmapped 60000")

    # FC 5 / 6 length; FC 5 value (the spec checks the value before the address).
    r.exc(pdu_write_single(5, 0, 0xFF00)[:4], ILLEGAL_VALUE, "FC 5 one byte short")
    r.exc(pdu_write_single(6, 4, 1) + b"\x00", ILLEGAL_VALUE, "FC 6 one byte long")
    for v in (0x0001, 0x00FF, 0xFF01, 0x1234, 0xFFFF):
        r.exc(pdu_write_single(5, 0, v), ILLEGAL_VALUE, "FC 5 value %04X" % v)
    r.exc(pdu_write_single(5, 5, 0x1234), ILLEGAL_VALUE, "FC 5 value 1234 at unmapped coil 5 (value first)")

    # FC 15: quantity, byte count, PDU length.
    r.exc(pdu_write_coils(8, [], quantity=0, byte_count=0), ILLEGAL_VALUE, "FC 15 quantity 0")
    r.exc(pdu_write_coils(8, [0] * 1969), ILLEGAL_VALUE, "FC 15 quantity 1969")
    r.exc(pdu_write_coils(8, [1] * 10, byte_count=1), ILLEGAL_VALUE, "FC 15 10 coils, byte count 1")
    r.exc(pdu_write_coils(8, [1] * 10, byte_count=3, extra=b"\x00"), ILLEGAL_VALUE, "FC 15 10 coils, byte count 3")
    r.exc(pdu_write_coils(8, [1] * 10, extra=b"\x00"), ILLEGAL_VALUE, "FC 15 one data byte more than the count")
    r.exc(pdu_write_coils(8, [1] * 10)[:-1], ILLEGAL_VALUE, "FC 15 one data byte less than the count")
    r.exc(pdu_write_coils(8, [1] * 10)[:5], ILLEGAL_VALUE, "FC 15 without byte count (PDU of 5)")

    # FC 16.
    r.exc(pdu_write_regs(1028, [], quantity=0, byte_count=0), ILLEGAL_VALUE, "FC 16 quantity 0")
    r.exc(pdu_write_regs(1028, [0] * 123, quantity=124), ILLEGAL_VALUE, "FC 16 quantity 124 (123 registers sent)")
    r.exc(pdu_write_regs(1028, [0] * 2, quantity=0xFFFF), ILLEGAL_VALUE, "FC 16 quantity 65535")
    r.exc(pdu_write_regs(1028, [1, 2], byte_count=2), ILLEGAL_VALUE, "FC 16 2 registers, byte count 2")
    r.exc(pdu_write_regs(1028, [1, 2], quantity=3), ILLEGAL_VALUE, "FC 16 quantity 3, byte count 4")
    r.exc(pdu_write_regs(1028, [1, 2], extra=b"\x00\x00"), ILLEGAL_VALUE, "FC 16 2 bytes past the count")
    r.exc(pdu_write_regs(1028, [1, 2])[:-1], ILLEGAL_VALUE, "FC 16 a byte short")
    r.exc(pdu_write_regs(60000, [1, 2], byte_count=5, extra=b"\x00"), ILLEGAL_VALUE,
          "FC 16 bad byte count at unmapped 60000 (03 before 02)")

    # FC 23.
    r.exc(pdu_rw(1024, 0, 1024, [1]), ILLEGAL_VALUE, "FC 23 read quantity 0")
    r.exc(pdu_rw(1024, 126, 1024, [1]), ILLEGAL_VALUE, "FC 23 read quantity 126")
    r.exc(pdu_rw(1024, 1, 1024, [], write_quantity=0, byte_count=0), ILLEGAL_VALUE, "FC 23 write quantity 0")
    r.exc(pdu_rw(1024, 1, 1024, [0] * 121, write_quantity=122), ILLEGAL_VALUE, "FC 23 write quantity 122")
    r.exc(pdu_rw(1024, 1, 1024, [0] * 121, write_quantity=122, byte_count=244), ILLEGAL_VALUE,
          "FC 23 write quantity 122, byte count 244 (242 bytes sent)")
    r.exc(pdu_rw(1024, 1, 1024, [1, 2], byte_count=2), ILLEGAL_VALUE, "FC 23 byte count 2 for 2 registers")
    r.exc(pdu_rw(1024, 1, 1024, [1])[:9], ILLEGAL_VALUE, "FC 23 PDU of 9")
    r.exc(pdu_rw(1024, 1, 1024, [1]) + b"\x00", ILLEGAL_VALUE, "FC 23 a byte past the count")

    # Values outside the tag's type (after the address checks pass).
    nan32, inf32, ninf32 = 0x7FC00000, 0x7F800000, 0xFF800000
    for bits in (nan32, inf32, ninf32, 0x7F800001, 0xFFFFFFFF):
        r.exc(pdu_write_regs(2114, [bits >> 16, bits & 0xFFFF]), ILLEGAL_VALUE, "REAL %08X" % bits)
    r.exc(pdu_write_regs(2108, [0, 1, 0, 2, 0, 3, nan32 >> 16, 0]), ILLEGAL_VALUE, "FC 16 of 4 values, the REAL a NaN")
    for bits in (0x7FF8000000000000, 0x7FF0000000000000, 0xFFF0000000000000, 0x7FF0000000000001):
        regs = list(struct.unpack(">HHHH", struct.pack(">Q", bits)))
        r.exc(pdu_write_regs(4228, regs), ILLEGAL_VALUE, "LREAL %016X" % bits)
        r.exc(pdu_rw(4268, 4, 4228, regs), ILLEGAL_VALUE, "FC 23 LREAL %016X" % bits)
    # pymodbus builds the NaN itself.
    peer.expect(ILLEGAL_VALUE, "write_registers", 2114, P.encode([("REAL", float("nan"))]), what="pymodbus REAL NaN")
    peer.expect(ILLEGAL_VALUE, "write_registers", 4228, P.encode([("LREAL", float("inf"))]), what="pymodbus LREAL inf")
    # An address error comes before a value error.
    r.exc(pdu_write_regs(2115, [nan32 >> 16, 0]), ILLEGAL_ADDRESS, "NaN into half a REAL (02 before 03)")


def illegal_address(peer, r):
    reads = [
        (1, 3, 1, "unmapped coil 3"), (1, 0, 18, "coils 0..17 over the gap 3..7"), (1, 18, 1, "coil 18"),
        (1, 17, 2, "coils 17..18"), (1, 65535, 1, "coil 65535"), (1, 65535, 2000, "coils 65535.. past 65535"),
        (2, 3, 1, "discrete input 3"), (2, 0, 9, "discrete inputs 0..8"), (2, 18, 1, "discrete input 18"),
        (4, 0, 1, "input register 0"), (4, 4, 4, "input registers 4..7"), (4, 3, 2, "input registers 3..4"),
        (3, 0, 1, "holding 0"), (3, 4, 7, "holding 4..10 (gap 7..9)"), (3, 1027, 1, "holding 1027"),
        (3, 1024, 8, "holding 1024..1031 over 1027"),
        (3, 2109, 1, "the low word of a DINT"), (3, 2108, 3, "a DINT and half a UDINT"),
        (3, 2115, 2, "half a REAL and past it"), (3, 4229, 2, "the middle of a LINT... LREAL"),
        (3, 4216, 3, "three quarters of a LINT"), (3, 4216, 21, "%ML30..34 and one more"),
        (3, 4235, 1, "the last word of a TIME"), (3, 65535, 1, "holding 65535"),
        (3, 65535, 125, "holding 65535.. past 65535"), (3, 65500, 125, "holding 65500.. past 65535"),
    ]
    for fc, address, q, what in reads:
        r.exc(pdu_read(fc, address, q), ILLEGAL_ADDRESS, "FC %d %s" % (fc, what))
    peer.expect(ILLEGAL_ADDRESS, "read_holding_registers", 2115, 1, what="pymodbus: the low word of a REAL")
    peer.expect(ILLEGAL_ADDRESS, "read_input_registers", 7, 1, what="pymodbus: input register 7")
    peer.expect(ILLEGAL_ADDRESS, "read_discrete_inputs", 5, 1, what="pymodbus: discrete input 5")

    # Writes: read-only tags, unmapped places, cut values.
    r.exc(pdu_write_single(5, 1, 0xFF00), ILLEGAL_ADDRESS, "FC 5 to read-only coil 1")
    r.exc(pdu_write_single(5, 3, 0xFF00), ILLEGAL_ADDRESS, "FC 5 to unmapped coil 3")
    r.exc(pdu_write_coils(0, [1, 1, 1]), ILLEGAL_ADDRESS, "FC 15 coils 0..2 (1 is read only)")
    r.exc(pdu_write_coils(17, [1, 1]), ILLEGAL_ADDRESS, "FC 15 coils 17 and unmapped 18")
    r.exc(pdu_write_single(6, 10, 1), ILLEGAL_ADDRESS, "FC 6 to read-only holding 10")
    r.exc(pdu_write_single(6, 1027, 1), ILLEGAL_ADDRESS, "FC 6 to unmapped holding 1027")
    r.exc(pdu_write_single(6, 2108, 1), ILLEGAL_ADDRESS, "FC 6 to one word of a DINT")
    r.exc(pdu_write_single(6, 4231, 1), ILLEGAL_ADDRESS, "FC 6 to one word of an LREAL")
    r.exc(pdu_write_regs(1034, [1]), ILLEGAL_ADDRESS, "FC 16 to read-only holding 1034")
    r.exc(pdu_write_regs(1030, [1, 2, 3]), ILLEGAL_ADDRESS, "FC 16 over the end of the array into 1032")
    r.exc(pdu_write_regs(2109, [1, 2]), ILLEGAL_ADDRESS, "FC 16 cutting a DINT and a UDINT")
    r.exc(pdu_write_regs(4228, [1, 2]), ILLEGAL_ADDRESS, "FC 16 of half an LREAL")
    r.exc(pdu_write_regs(2128, [0, 1]), ILLEGAL_ADDRESS, "FC 16 to a read-only DINT copy")
    r.exc(pdu_write_regs(65535, [1]), ILLEGAL_ADDRESS, "FC 16 to holding 65535")
    r.exc(pdu_rw(1024, 1, 1034, [5]), ILLEGAL_ADDRESS, "FC 23 writing a read-only register")
    r.exc(pdu_rw(1027, 1, 1024, [5]), ILLEGAL_ADDRESS, "FC 23 reading an unmapped register (nothing written)")
    r.exc(pdu_rw(2115, 1, 1024, [5]), ILLEGAL_ADDRESS, "FC 23 reading half a REAL (nothing written)")
    r.exc(pdu_rw(1024, 1, 4229, [1, 2]), ILLEGAL_ADDRESS, "FC 23 writing part of an LREAL")
    peer.expect(ILLEGAL_ADDRESS, "write_register", 11, 5, what="pymodbus FC 6 to read-only holding 11")
    peer.expect(ILLEGAL_ADDRESS, "write_coil", 1, True, what="pymodbus FC 5 to read-only coil 1")
    peer.expect(ILLEGAL_ADDRESS, "write_coils", 1, [True, False], what="pymodbus FC 15 to coils 1..2")
    peer.expect(ILLEGAL_ADDRESS, "write_registers", 2128, [0, 1, 0, 2], what="pymodbus FC 16 to read-only copies")
    peer.expect(ILLEGAL_ADDRESS, "readwrite_registers", read_address=1024, read_count=1, write_address=12,
                write_registers=[1], what="pymodbus FC 23 to read-only holding 12")


def gateway(peer, r, port, tally):
    for unit in (2, 7, 17, 100, 247, 254):
        r.exc(pdu_read(3, 1024, 1), GATEWAY_TARGET, "unit %d" % unit, unit=unit)
    # The unit is checked first: before the function code, the quantity and the address.
    r.exc(bytes([0x99]), GATEWAY_TARGET, "unit 2, unknown FC", unit=2)
    r.exc(pdu_read(3, 1024, 0), GATEWAY_TARGET, "unit 2, quantity 0", unit=2)
    r.exc(pdu_read(3, 1027, 1), GATEWAY_TARGET, "unit 2, unmapped", unit=2)
    r.exc(pdu_write_single(6, 1024, 9), GATEWAY_TARGET, "unit 2, a write (not applied)", unit=2)
    # 0 and 255 are answered like unit 1. The write of 77 (busy()) is
    # applied at task main's next scan: read once it is published.
    P.wait_until(lambda: (peer.read("holding", 1024, 1) == [77], None), "holding 1024 after busy()'s write of 77")
    for unit in (0, 255, 1):
        reply = r.ok(pdu_read(3, 1024, 1), "unit %d" % unit, unit=unit)
        if reply != bytes([3, 2, 0, 77]):
            raise AssertionError("unit %d: reading holding 1024 gave %s, expected 03 02 00 4D" % (unit, reply.hex(" ")))
    r.ok(pdu_write_single(6, 1025, 555), "FC 6 to unit 255", unit=255, written=1)
    u = P.Peer(port, tally, unit=3)
    u.expect(GATEWAY_TARGET, "read_holding_registers", 1024, 1, what="pymodbus slave=3")
    u.close()
    z = P.Peer(port, tally, unit=0)
    P.wait_until(lambda: (z.read("holding", 1035, 1) == [555], None), "holding 1035 after FC 6 to unit 255")
    z.close()


def refused_writes_changed_nothing(peer):
    want = {1024: [77, 555, 0x1234], 1028: [1, 2, 3, 4], 2108: [0xFFFF, 0xFFFE, 0x1234, 0x5678, 0xDEAD, 0xBEEF, 0x3F80, 0],
            4228: [0x3FF8, 0, 0, 0], 10: [0xFFFF, 40000, 0xBEEF]}
    for address, regs in want.items():
        got = peer.read("holding", address, len(regs))
        if got != regs:
            raise AssertionError("holding %d.. is %r after refused writes, expected %r" % (address, got, regs))
    for table, address, bits in (("coil", 0, [False, False, True]), ("coil", 8, [False] * 10)):
        got = peer.read(table, address, len(bits))
        if got != bits:
            raise AssertionError("%s %d.. is %r after refused writes, expected %r" % (table, address, got, bits))


def bad_frames(port, tally, r):
    """Not Modbus TCP: the server closes the connection, no reply."""
    cases = [
        ("protocol id 1", P.mbap(1, 1, pdu_read(3, 1024, 1), protocol=1)),
        ("protocol id FFFF", P.mbap(1, 1, pdu_read(3, 1024, 1), protocol=0xFFFF)),
        ("protocol id 1, header only", P.mbap(1, 1, b"", protocol=1)[:4]),
        ("length 0", P.mbap(1, 1, pdu_read(3, 1024, 1), length=0)),
        ("length 1", P.mbap(1, 1, pdu_read(3, 1024, 1), length=1)),
        ("length 255", P.mbap(1, 1, pdu_read(3, 1024, 1), length=255)),
        ("length 256 with 255 bytes", P.mbap(1, 1, bytes([3]) + b"\x00" * 254, length=256)),
        ("length FFFF", P.mbap(1, 1, pdu_read(3, 1024, 1), length=0xFFFF)),
        ("an HTTP request", b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"),
        ("TLS client hello bytes", bytes.fromhex("16030100a5010000a10303") + b"\x00" * 32),
        ("0xFF garbage", b"\xff" * 64),
    ]
    for what, data in cases:
        s = P.connect(port)
        tally.connection()
        s.sendall(data)
        if not P.closed_by_server(s, 10.0):
            raise AssertionError("%s: the server kept the connection open" % what)
        tally.closed_bad_frame += 1
        s.close()
    # A good request, answered; then garbage on the same connection: closed.
    s = P.connect(port)
    tally.connection()
    reply = P.transact(s, P.mbap(9, 1, pdu_read(3, 1024, 1)))
    if reply != bytes([3, 2, 0, 77]):
        raise AssertionError("good request before garbage: %s" % reply.hex(" "))
    tally.ok()
    s.sendall(P.mbap(10, 1, pdu_read(3, 1024, 1), protocol=7))
    if not P.closed_by_server(s, 10.0):
        raise AssertionError("protocol id 7 after a good request: the server kept the connection open")
    tally.closed_bad_frame += 1
    s.close()
    # Two good requests in one segment, then a bad header: both answered, then closed.
    s = P.connect(port)
    tally.connection()
    s.sendall(P.mbap(1, 1, pdu_read(3, 1024, 1)) + P.mbap(2, 1, pdu_read(1, 8, 10)) + b"\x00\x03\x00\x05\x00\x06")
    for tid in (1, 2):
        got_tid, _, pdu = P.recv_reply(s)
        if got_tid != tid:
            raise AssertionError("pipelined replies out of order: %d, expected %d" % (got_tid, tid))
        tally.ok()
    if not P.closed_by_server(s, 10.0):
        raise AssertionError("bad header after two pipelined requests: the server kept the connection open")
    tally.closed_bad_frame += 1
    s.close()
    # The connection that has seen everything above still works.
    r.ok(pdu_read(3, 1024, 1), "after the bad frames")


def random_pdus(r, seed=20260522):
    """Random bodies in well-formed frames: each gets a well-formed reply, the connection stays."""
    rng = random.Random(seed)
    kinds = [1, 2, 3, 4, 5, 6, 15, 16, 23, 0x11, 0x2B, 0x80, 0xC3]
    for i in range(400):
        fc = rng.choice(kinds)
        body = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 20)))
        if fc in (5, 6, 15, 16, 23) and len(body) >= 2:
            # Keep writes away from the writable tags: a random address in 20000..59999.
            address = rng.randrange(20000, 60000)
            body = struct.pack(">H", address) + body[2:]
            if fc == 23 and len(body) >= 6:
                body = body[:4] + struct.pack(">H", rng.randrange(20000, 60000)) + body[6:]
        reply = r.any(bytes([fc]) + body)
        if reply[0] == fc and fc in (5, 6, 15, 16, 23):
            raise AssertionError("random write FC %d %s was accepted" % (fc, body.hex(" ")))


def vanishing_clients(port, tally, r):
    """Clients that disconnect in the middle of a frame, with FIN or with a reset."""
    half = P.mbap(1, 1, pdu_read(3, 1024, 1))[:9]
    for how in ("fin", "rst", "shutdown"):
        for cut in (1, 3, 5, 7, 9):
            s = P.connect(port)
            tally.connection()
            s.sendall(half[:cut])
            time.sleep(0.002)
            if how == "rst":
                s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
                s.close()
            elif how == "shutdown":
                s.shutdown(socket.SHUT_WR)
                if not P.closed_by_server(s, 10.0):
                    raise AssertionError("half-closed after %d bytes: the server kept the connection" % cut)
                s.close()
            else:
                s.close()
    # An answered request, then half of the next one, then gone.
    s = P.connect(port)
    tally.connection()
    reply = P.transact(s, P.mbap(5, 1, pdu_read(3, 1024, 1)))
    tally.ok()
    s.sendall(P.mbap(6, 1, pdu_write_regs(1028, [9, 9, 9, 9]))[:15])
    s.close()
    # An FC 23 sent, and the client gone before its reply (the write still happens).
    s = P.connect(port)
    tally.connection()
    s.sendall(P.mbap(7, 1, pdu_rw(1038, 4, 1028, [41, 42, 43, 44])))
    s.close()
    tally.ok(written=4)
    # The server goes on: the long-lived connection still gets answers, and the FC 23 was applied.
    P.wait_until(lambda: (lambda v: (v == [41, 42, 43, 44], v))(
        list(struct.unpack(">4H", r.ok(pdu_read(3, 1038, 4), "array copy after a vanished FC 23")[2:]))),
        "array copy (holding 1038..1041) after the FC 23 whose client vanished")
    # Put the array back for refused_writes_changed_nothing's sake.
    r.ok(pdu_write_regs(1028, [1, 2, 3, 4]), "array back to 1, 2, 3, 4", written=4)


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers.yaml"))
    try:
        busy(server.port, tally)  # first: the slow task's queue drains only every 10 s
        peer = P.Peer(server.port, tally)
        r = Raw(server.port, tally)
        illegal_function(peer, r)
        illegal_value(peer, r)
        illegal_address(peer, r)
        gateway(peer, r, server.port, tally)
        refused_writes_changed_nothing(peer)
        bad_frames(server.port, tally, r)
        random_pdus(r)
        vanishing_clients(server.port, tally, r)
        # Reads make the count of polls above exact; wait until every vanished client is closed.
        time.sleep(0.2)
        refused_writes_changed_nothing(peer)
        peer.close()
        r.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_exceptions: OK (%d requests, exceptions %r)" % (tally.requests, tally.by_code))


if __name__ == "__main__":
    sys.exit(main())
