"""pymodbus (Debian's python3-pymodbus) against `syncplc run tests/peers/peers.yaml`:
every area and type read (FC 1, 2, 3, 4), every writable type written (FC 5,
6, 15, 16, 23) and seen in its read-only copy after the next scan(s), REAL and
LREAL round trips with the default word order (high word first), and the
server's counters at the end.

    /usr/bin/python3 tests/peers/test_read_write.py build/syncplc
"""

import math
import struct
import sys

import peerlib as P

INT16 = lambda v: v & 0xFFFF  # noqa: E731  a signed value as the register holds it

MD, MD_R, MD_T = P.MD, P.MD_R, P.MD_T
ML, ML_R, ML_T = P.ML, P.ML_R, P.ML_T


check = P.check_equal


check_values = P.check_values


def reads(peer):
    """Every area and type at its initial value."""
    # The first scan runs before the server starts, but wait for it anyway.
    peer.wait_read("discrete", 0, 1, [True], "discrete input 0 (i_true, a constant TRUE)")
    check(peer.read("coil", 0, 3), [False, False, True], "coils 0..2 (q_cmd, q_echo, q_init)")
    check(peer.read("coil", 8, 10), [False] * 10, "coils 8..17 (q_arr)")
    check(peer.read("coil", 2, 1), [True], "coil 2 alone")
    check(peer.read("discrete", 0, 3), [True, False, False], "discrete inputs 0..2 (i_true, i_echo, i_drv)")
    check(peer.read("discrete", 8, 10), [False] * 10, "discrete inputs 8..17 (i_arr)")
    check(peer.read("input", 4, 3), [INT16(-1234), 0xBEEF, 0], "input registers 4..6 (INT, WORD, UINT)")
    check(peer.read("holding", 4, 3), [INT16(-1), 40000, 0xBEEF], "holding 4..6 (%QW INT, UINT, WORD)")
    check(peer.read("holding", 10, 3), [INT16(-1), 40000, 0xBEEF], "holding 10..12 (their copies)")
    check(peer.read("holding", 1024, 3), [1000, 2000, 0x1234], "holding 1024..1026 (%MW INT, UINT, WORD)")
    check(peer.read("holding", 1028, 4), [1, 2, 3, 4], "holding 1028..1031 (%MW ARRAY OF INT)")
    check(peer.read("holding", 1034, 3), [1000, 2000, 0x1234], "holding 1034..1036 (copies)")
    check(peer.read("holding", 1038, 4), [1, 2, 3, 4], "holding 1038..1041 (array copy)")
    check(peer.read("holding", 1074, 1), [0], "holding 1074 (slow_set)")
    check(peer.read("holding", 1624, 125), [0x5A5A] * 125, "holding 1624..1748 (125 WORDs, the largest read)")
    # The worked examples of docs/modbus.md, as raw registers.
    check(peer.read("holding", MD, 8), [0xFFFF, 0xFFFE, 0x1234, 0x5678, 0xDEAD, 0xBEEF, 0x3F80, 0x0000],
          "holding 2108..2115 (DINT -2, UDINT 16#12345678, DWORD 16#DEADBEEF, REAL 1.0), high word first")
    check(peer.read("holding", ML + 12, 4), [0x3FF8, 0, 0, 0], "holding 4228..4231 (LREAL 1.5)")
    init_md = [-2, 0x12345678, 0xDEADBEEF, 1.0]
    init_ml = [-3, 0x0123456789ABCDEF, 0xFEDCBA9876543210, 1.5, 1_500_000_000]
    check_values(MD_T, peer.read_values(MD, MD_T), init_md, "%MD30..33 decoded")
    check_values(MD_T, peer.read_values(MD_R, MD_T), init_md, "%MD40..43 (copies) decoded")
    check_values(ML_T, peer.read_values(ML, ML_T), init_ml, "%ML30..34 decoded")
    check_values(ML_T, peer.read_values(ML_R, ML_T), init_ml, "%ML40..44 (copies) decoded")
    # Single values out of a block, and the largest read (125 registers: 4216..4340 is not all
    # mapped, so read the 20 + 20 of the two %ML blocks separately; 2108..2135 has a gap too).
    check_values(["REAL"], peer.read_values(MD + 6, ["REAL"]), [1.0], "REAL alone")
    check_values(["TIME"], peer.read_values(ML + 16, ["TIME"]), [1_500_000_000], "TIME alone")


def writes(peer):
    # FC 5: a coil; its copies are a read-only coil and a discrete input.
    peer.write_coil(0, True)
    peer.wait_read("coil", 1, 1, [True], "coil 1 (q_echo) after FC 5 coil 0 := 1")
    check(peer.read("discrete", 1, 1), [True], "discrete input 1 (i_echo) after FC 5")
    check(peer.read("coil", 0, 1), [True], "coil 0 after FC 5")
    peer.write_coil(0, False)
    peer.wait_read("discrete", 1, 1, [False], "discrete input 1 after FC 5 coil 0 := 0")
    # FC 15: the BOOL array, whole and in part.
    pattern = [True, False, True, True, False, False, True, False, False, True]
    peer.write_coils(8, pattern)
    peer.wait_read("discrete", 8, 10, pattern, "discrete inputs 8..17 (i_arr) after FC 15 of coils 8..17")
    check(peer.read("coil", 8, 10), pattern, "coils 8..17 after FC 15")
    peer.write_coils(11, [False, True, True])
    pattern[3:6] = [False, True, True]
    peer.wait_read("discrete", 8, 10, pattern, "discrete inputs 8..17 after FC 15 of coils 11..13")
    # Coil 1 (q_echo) is read only, so coils 0..2 cannot be written in one request
    # (test_exceptions): FC 15 of one coil each.
    peer.write_coils(0, [True])
    peer.write_coils(2, [False])
    peer.wait_read("coil", 0, 3, [True, True, False], "coils 0..2 after FC 15 to 0 (and 2)")

    # FC 6: every 16-bit type, %QW and %MW; the WORD also comes back as input register 5.
    peer.write_register(4, INT16(-5))
    peer.write_register(5, 65535)
    peer.write_register(6, 0xA5A5)
    peer.wait_read("holding", 10, 3, [INT16(-5), 65535, 0xA5A5], "holding 10..12 after FC 6 to 4, 5, 6")
    peer.wait_read("input", 5, 1, [0xA5A5], "input register 5 (iw_echo) after FC 6 to WORD 6")
    peer.write_register(1024, INT16(-32768))
    peer.write_register(1025, 0)
    peer.write_register(1026, 0xFFFF)
    peer.wait_read("holding", 1034, 3, [INT16(-32768), 0, 0xFFFF], "holding 1034..1036 after FC 6")
    peer.write_register(1028 + 2, INT16(-7))
    peer.wait_read("holding", 1038, 4, [1, 2, INT16(-7), 4], "array copy after FC 6 to element 2")

    # FC 16: 16-bit values, a whole array, then every 32- and 64-bit type in one request each.
    peer.write_registers(4, [INT16(32767), 1, 0x0F0F], 3)
    peer.wait_read("holding", 10, 3, [32767, 1, 0x0F0F], "holding 10..12 after FC 16")
    peer.write_registers(1028, [10, INT16(-20), 30, 32767], 4)
    peer.wait_read("holding", 1038, 4, [10, INT16(-20), 30, 32767], "array copy after FC 16")
    md = [-123456789, 4_000_000_000, 0xCAFEBABE, -2.5]
    peer.write_values(MD, list(zip(MD_T, md)))
    peer.wait_values(MD_R, MD_T, md, "%MD copies after FC 16 of DINT, UDINT, DWORD, REAL")
    check_values(MD_T, peer.read_values(MD, MD_T), md, "%MD30..33 after FC 16")
    ml = [-(2 ** 63), 2 ** 64 - 1, 0x0011223344556677, -1e300, -2_500_000_000]
    peer.write_values(ML, list(zip(ML_T, ml)))
    peer.wait_values(ML_R, ML_T, ml, "%ML copies after FC 16 of LINT, ULINT, LWORD, LREAL, TIME")
    check_values(ML_T, peer.read_values(ML, ML_T), ml, "%ML30..34 after FC 16")
    # Each 32/64-bit type alone (FC 16 of its 2 or 4 registers).
    singles = [(MD, MD_R, "DINT", 2 ** 31 - 1), (MD + 2, MD_R + 2, "UDINT", 0),
               (MD + 4, MD_R + 4, "DWORD", 0xFFFFFFFF), (ML, ML_R, "LINT", 2 ** 63 - 1),
               (ML + 4, ML_R + 4, "ULINT", 0), (ML + 8, ML_R + 8, "LWORD", 0x8000000000000001),
               (ML + 16, ML_R + 16, "TIME", 86_400_000_000_000)]
    for at, copy, t, v in singles:
        peer.write_values(at, [(t, v)])
        peer.wait_values(copy, [t], [v], "%s copy at %d after FC 16 of %d" % (t, copy, v))

    # FC 23: the reply comes after the write is published, so the read part already shows
    # the program's copy of the value written in the same request.
    got = peer.readwrite(MD_R + 6, 2, MD + 6, P.encode([("REAL", 3.25)]), 1)
    check_values(["REAL"], P.decode(["REAL"], got), [3.25], "FC 23: md_real := 3.25, read md_real_r")
    got = peer.readwrite(ML_R, 20, ML, P.encode(list(zip(ML_T, [7, 8, 9, 0.125, 10]))), 5)
    check_values(ML_T, P.decode(ML_T, got), [7, 8, 9, 0.125, 10], "FC 23: every %ML, read their copies")
    got = peer.readwrite(10, 3, 4, [INT16(-300), 300, 0x0300], 3)
    check(got, [INT16(-300), 300, 0x0300], "FC 23: %QW4..6, read holding 10..12")
    got = peer.readwrite(1024, 3, 1024, [11, 12, 13], 3)
    check(got, [11, 12, 13], "FC 23 reading the registers it writes")
    got = peer.readwrite(1038, 4, 1029, [21, 22], 2)
    check(got, [10, 21, 22, 32767], "FC 23: elements 1 and 2 of the array, read the copy")


def real_round_trips(peer):
    """REAL and LREAL, high word first (pymodbus word order Endian.Big), FC 16 and FC 23."""
    reals = [0.1, -0.0, 1.0e-40, 3.4028234663852886e38, -3.4028234663852886e38, math.pi, -1.5, 1e-45]
    for v in reals:
        f32 = struct.unpack(">f", struct.pack(">f", v))[0]
        peer.write_values(MD + 6, [("REAL", v)])
        peer.wait_values(MD_R + 6, ["REAL"], [f32], "REAL %r round trip (copy)" % v)
        got = peer.read("holding", MD + 6, 2)
        check(got, list(struct.unpack(">HH", struct.pack(">f", v))), "REAL %r registers, high word first" % v)
    lreals = [0.1, -0.0, 5e-324, 1.7976931348623157e308, -1.7976931348623157e308, math.e, 1.0 / 3.0]
    for v in lreals:
        peer.write_values(ML + 12, [("LREAL", v)])
        peer.wait_values(ML_R + 12, ["LREAL"], [v], "LREAL %r round trip (copy)" % v)
        got = peer.read("holding", ML + 12, 4)
        check(got, list(struct.unpack(">HHHH", struct.pack(">d", v))), "LREAL %r registers, high word first" % v)
        got = peer.readwrite(ML_R + 12, 4, ML + 12, P.encode([("LREAL", -v)]), 1)
        check_values(["LREAL"], P.decode(["LREAL"], got), [-v], "FC 23 LREAL %r" % -v)


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers.yaml"))
    if server.unit != 1 or server.mapped != 193:
        raise AssertionError("expected unit 1 and 193 values mapped, got unit %s, %s mapped" % (server.unit, server.mapped))
    try:
        peer = P.Peer(server.port, tally)
        reads(peer)
        writes(peer)
        real_round_trips(peer)
        # A second connection sees the same values (one snapshot, not per connection).
        other = P.Peer(server.port, tally)
        check(other.read("holding", 1024, 3), [11, 12, 13], "a second client reads holding 1024..1026")
        other.close()
        peer.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_read_write: OK (%d requests)" % tally.requests)


if __name__ == "__main__":
    sys.exit(main())
