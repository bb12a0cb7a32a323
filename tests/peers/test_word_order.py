"""Word order low_first and explicit Modbus places, against
`syncplc run tests/peers/peers_low_first.yaml` (modbus: {word_order: low_first}):

- 32/64-bit values low word first on the wire (docs/modbus.md's worked
  examples), decoded and encoded by pymodbus with word order Endian.Little;
  REAL and LREAL round trips (FC 16 and FC 23) through the program's copies;
  the finite check applied after the words are put in order;
- mbpoll, whose 32-bit types are low word first unless -B, reading and
  writing int and float;
- SINT, USINT and BYTE at explicit holding registers: read, written (FC 6,
  16, 23), sign extension, values outside the type refused with 03 and nothing
  written; a readwrite tag in the input-register table cannot be written
  (02); a REAL at explicit input registers; an explicit coil and discrete input.

    /usr/bin/python3 tests/peers/test_word_order.py build/syncplc
"""

import math
import struct
import sys

import peerlib as P
from test_exceptions import Raw, pdu_read, pdu_rw, pdu_write_regs, pdu_write_single

LOW = "low_first"
MD, MD_R, MD_T = P.MD, P.MD_R, P.MD_T
ML, ML_R, ML_T = P.ML, P.ML_R, P.ML_T


check = P.check_equal


check_values = P.check_values


def words_low_first(fmt, value):
    regs = list(struct.unpack(">%dH" % (struct.calcsize(fmt) // 2), struct.pack(">" + fmt, value)))
    return regs[::-1]


def low_first(peer, r):
    peer.wait_read("discrete", 0, 1, [True], "discrete input 0 after the first scan")
    check(peer.read("holding", MD, 8), [0xFFFE, 0xFFFF, 0x5678, 0x1234, 0xBEEF, 0xDEAD, 0x0000, 0x3F80],
          "DINT -2, UDINT 16#12345678, DWORD 16#DEADBEEF, REAL 1.0 low word first (docs/modbus.md)")
    check(peer.read("holding", ML + 12, 4), [0, 0, 0, 0x3FF8], "LREAL 1.5 low word first")
    check(peer.read("holding", 4, 3), [0xFFFF, 40000, 0xBEEF], "16-bit registers are not affected")
    init_md = [-2, 0x12345678, 0xDEADBEEF, 1.0]
    init_ml = [-3, 0x0123456789ABCDEF, 0xFEDCBA9876543210, 1.5, 1_500_000_000]
    check_values(MD_T, peer.read_values(MD, MD_T, word_order=LOW), init_md, "%MD decoded low word first")
    check_values(MD_T, peer.read_values(MD_R, MD_T, word_order=LOW), init_md, "%MD copies decoded low word first")
    check_values(ML_T, peer.read_values(ML, ML_T, word_order=LOW), init_ml, "%ML decoded low word first")
    check_values(ML_T, peer.read_values(ML_R, ML_T, word_order=LOW), init_ml, "%ML copies decoded low word first")
    wrong = peer.read_values(MD + 6, ["REAL"])[0]  # decoded high word first: not 1.0
    if wrong == 1.0:
        raise AssertionError("REAL 1.0 decoded with the wrong word order still gives 1.0")
    # The REAL copy in explicit input registers 3200..3201.
    check(peer.read("input", 3200, 2), [0, 0x3F80], "ir_real (= md_real 1.0) in input registers, low word first")

    # Writes of every 32/64-bit type, low word first.
    md = [-123456789, 4_000_000_000, 0xCAFEBABE, -2.5]
    peer.write_values(MD, list(zip(MD_T, md)), LOW)
    peer.wait_values(MD_R, MD_T, md, "%MD copies after FC 16 low word first", word_order=LOW)
    check(peer.read("holding", MD, 2), words_low_first("i", -123456789), "DINT registers")
    ml = [-(2 ** 62) - 5, 2 ** 64 - 2, 0x1122334455667788, -1e-300, 3_600_000_000_000]
    peer.write_values(ML, list(zip(ML_T, ml)), LOW)
    peer.wait_values(ML_R, ML_T, ml, "%ML copies after FC 16 low word first", word_order=LOW)
    check(peer.read("holding", ML + 4, 4), words_low_first("Q", 2 ** 64 - 2), "ULINT registers")
    P.wait_until(lambda: (lambda v: (v == words_low_first("f", -2.5), v))(peer.read("input", 3200, 2)),
                 "ir_real after md_real := -2.5")

    # REAL and LREAL round trips (pymodbus Endian.Little word order), FC 16 and FC 23.
    for v in (0.1, -0.0, 1.0e-40, 3.4028234663852886e38, math.pi, -1.5, 1e-45):
        f32 = struct.unpack(">f", struct.pack(">f", v))[0]
        peer.write_values(MD + 6, [("REAL", v)], LOW)
        peer.wait_values(MD_R + 6, ["REAL"], [f32], "REAL %r round trip, low word first" % v, word_order=LOW)
        check(peer.read("holding", MD + 6, 2), words_low_first("f", v), "REAL %r registers low word first" % v)
        got = peer.readwrite(MD_R + 6, 2, MD + 6, P.encode([("REAL", -v)], LOW), 1)
        check_values(["REAL"], P.decode(["REAL"], got, LOW), [-f32], "FC 23 REAL %r low word first" % -v)
    for v in (0.1, -0.0, 5e-324, 1.7976931348623157e308, math.e, -1.0 / 3.0):
        peer.write_values(ML + 12, [("LREAL", v)], LOW)
        peer.wait_values(ML_R + 12, ["LREAL"], [v], "LREAL %r round trip, low word first" % v, word_order=LOW)
        check(peer.read("holding", ML + 12, 4), words_low_first("d", v), "LREAL %r registers low word first" % v)
        got = peer.readwrite(ML_R + 12, 4, ML + 12, P.encode([("LREAL", -v)], LOW), 1)
        check_values(["LREAL"], P.decode(["LREAL"], got, LOW), [-v], "FC 23 LREAL %r low word first" % -v)

    # The finite check sees the value in the configured order: 7FC0 0000 is a NaN high word
    # first, but low word first it is 0x00007FC0, a tiny finite REAL.
    r.exc(pdu_write_regs(MD + 6, [0x0000, 0x7FC0]), 0x03, "REAL NaN written low word first")
    r.exc(pdu_write_regs(ML + 12, [0, 0, 0, 0x7FF0]), 0x03, "LREAL +inf written low word first")
    r.ok(pdu_write_regs(MD + 6, [0x7FC0, 0x0000]), "7FC0 0000 low word first: REAL 16#00007FC0", written=1)
    tiny = struct.unpack(">f", bytes.fromhex("00007FC0"))[0]
    peer.wait_values(MD_R + 6, ["REAL"], [tiny], "REAL copy after 7FC0 0000 low word first", word_order=LOW)


def places(peer, r):
    """SINT, USINT, BYTE at explicit holding registers; an input-register readwrite tag; explicit bits."""
    check(peer.read("holding", 3000, 3), [0xFFFB, 200, 0xA5], "SINT -5 (sign-extended), USINT 200, BYTE 16#A5")
    peer.wait_read("holding", 3010, 3, [0xFFFB, 200, 0xA5], "their copies")
    for address, value, name in ((3000, 0xFF80, "SINT -128"), (3000, 0x007F, "SINT 127"), (3001, 255, "USINT 255"),
                                 (3001, 0, "USINT 0"), (3002, 0xFF, "BYTE 16#FF")):
        peer.write_register(address, value)
        peer.wait_read("holding", address + 10, 1, [value], "copy after FC 6 %s" % name)
    for address, value, name in ((3000, 0x0080, "SINT 128"), (3000, 0xFF7F, "SINT -129"), (3000, 0x8000, "SINT -32768"),
                                 (3000, 0x0100, "SINT 256"), (3001, 256, "USINT 256"), (3001, 0xFFFF, "USINT 65535"),
                                 (3002, 0x0100, "BYTE 256"), (3002, 0x8000, "BYTE 32768")):
        r.exc(pdu_write_single(6, address, value), 0x03, "FC 6 %s (outside the type)" % name)
    # FC 16 of the three: one value outside its type refuses the whole request.
    r.exc(pdu_write_regs(3000, [0xFFFF, 300, 1]), 0x03, "FC 16 with USINT 300")
    check(peer.read("holding", 3010, 3), [0x007F, 0, 0xFF], "copies unchanged after the refused FC 16")
    peer.write_registers(3000, [0xFFFF, 1, 0x5A], 3)
    peer.wait_read("holding", 3010, 3, [0xFFFF, 1, 0x5A], "copies after FC 16 (SINT -1, USINT 1, BYTE 16#5A)")
    got = peer.readwrite(3010, 3, 3000, [0xFF9C, 99, 0x11], 3)
    check(got, [0xFF9C, 99, 0x11], "FC 23 writing SINT -100, USINT 99, BYTE 16#11, reading the copies")
    r.exc(pdu_rw(3010, 3, 3000, [0x0100, 1, 1]), 0x03, "FC 23 with SINT 256")
    r.exc(pdu_write_regs(3000, [1, 2, 3, 4]), 0x02, "FC 16 3000..3003 (3003 unmapped)")
    r.exc(pdu_write_single(6, 3010, 1), 0x02, "FC 6 to the read-only SINT copy")

    # A readwrite tag in the input-register table: readable, never writable.
    check(peer.read("input", 3100, 1), [42], "ir_rw (INT 42) at input register 3100")
    r.exc(pdu_write_single(6, 3100, 1), 0x02, "FC 6 to 3100 (only an input register there)")
    r.exc(pdu_write_regs(3100, [1]), 0x02, "FC 16 to 3100")
    r.exc(pdu_read(4, 3201, 1), 0x02, "the second word of the REAL in input registers")
    check(peer.read("input", 3100, 1), [42], "ir_rw unchanged")

    # Explicit coil 5000 and its copy, discrete input 5000.
    peer.write_coil(5000, True)
    peer.wait_read("discrete", 5000, 1, [True], "discrete input 5000 after FC 5 coil 5000 := 1")
    peer.write_coils(5000, [False])
    peer.wait_read("discrete", 5000, 1, [False], "discrete input 5000 after FC 15 coil 5000 := 0")
    r.exc(pdu_read(1, 4999, 2), 0x02, "coils 4999..5000")


def mbpoll_low_first(port, tally):
    from test_mbpoll import Mbpoll
    m = Mbpoll(port, tally)
    # mbpoll's 32-bit types are low word first without -B: no -B here.
    def values(table, ref, count, fmt, conv):
        r = m.run(["-t", "%d%s" % (table, fmt), "-r", str(ref), "-c", str(count), "-0"])
        tally.ok()
        import re
        return [conv(v) for v in re.findall(r"^\[\d+\]:\s+(\S+)", r.stdout, re.M)]

    m.run(["-t", "4:float", "-r", "2114", "-0"], [6.5])
    tally.ok(written=1)
    P.wait_until(lambda: (lambda v: (v == [6.5], v))(values(4, 2134, 1, ":float", float)),
                 "mbpoll: REAL copy after mbpoll wrote 6.5 low word first")
    P.wait_until(lambda: (lambda v: (v == [6.5], v))(values(3, 3200, 1, ":float", float)),
                 "mbpoll: ir_real (input registers 3200..3201) as a float, low word first")
    m.run(["-t", "4:int", "-r", "2108", "-0"], [-7654321])
    tally.ok(written=1)
    P.wait_until(lambda: (lambda v: (v == [-7654321], v))(values(4, 2128, 1, ":int", int)),
                 "mbpoll: DINT copy after mbpoll wrote -7654321 low word first")
    check(values(4, 2110, 1, ":int", int), [4_000_000_000 - 2 ** 32], "mbpoll: UDINT 4e9 as a signed int")
    # SINT, USINT, BYTE at explicit holding registers (as FC 23 left them) and the INT in input registers.
    check(values(4, 3000, 3, "", int), [0xFF9C, 99, 0x11], "mbpoll: SINT -100, USINT 99, BYTE 16#11 at 3000..3002")
    check(values(4, 3010, 3, ":hex", lambda x: int(x, 16)), [0xFF9C, 99, 0x11], "mbpoll: their copies, hex")
    check(values(3, 3100, 1, "", int), [42], "mbpoll: ir_rw at input register 3100")
    m.run(["-t", "4", "-r", "3000", "-0"], [0xFF85, 250, 0xFF])
    tally.ok(written=3)
    P.wait_until(lambda: (lambda v: (v == [0xFF85, 250, 0xFF], v))(values(4, 3010, 3, "", int)),
                 "mbpoll: copies after mbpoll wrote SINT -123, USINT 250, BYTE 16#FF")
    r = m.run(["-t", "4", "-r", "3001", "-0"], [256], ok=False)
    tally.exception(0x03)
    if "Illegal data value" not in r.stdout:
        raise AssertionError("mbpoll writing USINT 256: expected Illegal data value:\n" + r.stdout)


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_low_first.yaml"))
    if server.mapped != 203:
        raise AssertionError("expected 78 values mapped (193 + 10 explicit), got %s" % server.mapped)
    try:
        peer = P.Peer(server.port, tally)
        r = Raw(server.port, tally)
        low_first(peer, r)
        places(peer, r)
        mbpoll_low_first(server.port, tally)
        peer.close()
        r.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_word_order: OK (%d requests)" % tally.requests)


if __name__ == "__main__":
    sys.exit(main())
