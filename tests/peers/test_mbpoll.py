"""mbpoll (Debian's mbpoll, libmodbus inside) against `syncplc run tests/peers/peers.yaml`:
every area read, in mbpoll's 1-based references and with -0 (PDU addresses);
writes of coils and registers (FC 5, 6, 15, 16; 32-bit int and float with -B,
high word first) read back through the program's read-only copies; the
exceptions mbpoll reports; the server's counters at the end. Every mbpoll run
is one connection and one request.

    /usr/bin/python3 tests/peers/test_mbpoll.py build/syncplc
"""

import re
import struct
import sys
import time

import peerlib as P

MBPOLL = "/usr/bin/mbpoll"


class Mbpoll:
    def __init__(self, port, tally):
        self.port = port
        self.tally = tally

    def run(self, args, values=(), ok=True):
        """mbpoll once; returns {reference: text} of what it printed, or its output on failure."""
        cmd = [MBPOLL, "-m", "tcp", "-p", str(self.port), "-1", "-o", "5", *args, "127.0.0.1"]
        if values:
            cmd += ["--", *[str(v) for v in values]]
        r = P.run(cmd, timeout=60)
        self.tally.connection()
        if ok and r.returncode != 0:
            raise AssertionError("%s failed (status %d):\n%s" % (" ".join(cmd), r.returncode, r.stdout))
        return r

    def read(self, table, ref, count=1, zero_based=True, fmt=""):
        """Reads `count` values of mbpoll table `table` (0 coil, 1 input, 3 input register, 4 holding)."""
        args = ["-t", "%d%s" % (table, fmt), "-r", str(ref), "-c", str(count)]
        if zero_based:
            args.append("-0")
        if fmt in (":int", ":float"):
            args.append("-B")  # high word first, the server's default
        r = self.run(args)
        self.tally.ok()
        out = {}
        for m in re.finditer(r"^\[(\d+)\]:\s+(\S+)", r.stdout, re.M):
            out[int(m.group(1))] = m.group(2)
        want = count
        if len(out) != want:
            raise AssertionError("mbpoll %s printed %d values, expected %d:\n%s" % (" ".join(args), len(out), want, r.stdout))
        return out

    def values(self, table, ref, count=1, zero_based=True, fmt="", conv=int):
        d = self.read(table, ref, count, zero_based, fmt)
        return [conv(d[k]) for k in sorted(d)]

    def write(self, table, ref, values, written, fmt=""):
        args = ["-t", "%d%s" % (table, fmt), "-r", str(ref), "-0"]
        if fmt in (":int", ":float"):
            args.append("-B")
        r = self.run(args, values)
        if "Written %d references" % len(values) not in r.stdout:
            raise AssertionError("mbpoll did not confirm the write:\n" + r.stdout)
        self.tally.ok(written=written)

    def fails(self, args, values, code, message):
        """A request that gets exception `code`: mbpoll says `message`."""
        r = self.run(args, values, ok=False)
        self.tally.exception(code)
        if message not in r.stdout:
            raise AssertionError("mbpoll %s: expected %r in its output:\n%s" % (" ".join(args), message, r.stdout))
        return r

    def wait(self, table, ref, count, want, what, fmt="", conv=int):
        deadline = time.monotonic() + P.ECHO_TIMEOUT
        while True:
            got = self.values(table, ref, count, True, fmt, conv)
            if got == want:
                return
            if time.monotonic() > deadline:
                raise AssertionError("%s: mbpoll reads %r, expected %r" % (what, got, want))
            time.sleep(0.01)


check = P.check_equal


def hex_regs(s):
    return int(s, 16)


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers.yaml"))
    m = Mbpoll(server.port, tally)
    try:
        m.wait(1, 0, 1, [1], "discrete input 0 (i_true)")
        # --- every area, 0-based (-0) and 1-based references --------------------------------
        check(m.values(0, 0, 3), [0, 0, 1], "coils 0..2 (-0)")
        check(m.values(0, 1, 3, zero_based=False), [0, 0, 1], "coils 0..2 as references 1..3")
        check(m.values(0, 8, 10), [0] * 10, "coils 8..17 (BOOL array)")
        check(m.values(1, 0, 3), [1, 0, 0], "discrete inputs 0..2")
        check(m.values(1, 9, 10, zero_based=False), [0] * 10, "discrete inputs 8..17 as references 9..18")
        check(m.values(3, 4, 3), [64302, 0xBEEF, 0], "input registers 4..6 (INT -1234, WORD, UINT)")
        check(m.values(3, 5, 3, zero_based=False, fmt=":hex", conv=hex_regs), [0xFB2E, 0xBEEF, 0],
              "input registers 4..6 as references 5..7, hex")
        check(m.values(4, 4, 3), [0xFFFF, 40000, 0xBEEF], "holding 4..6 (%QW INT -1, UINT, WORD)")
        check(m.values(4, 11, 3, zero_based=False), [0xFFFF, 40000, 0xBEEF], "holding 10..12 as references 11..13")
        check(m.values(4, 1024, 3), [1000, 2000, 0x1234], "holding 1024..1026 (%MW)")
        check(m.values(4, 1028, 4), [1, 2, 3, 4], "holding 1028..1031 (%MW array)")
        check(m.values(4, 2108, 2, fmt=":int"), [-2, 0x12345678], "DINT, UDINT as mbpoll 32-bit ints (-B)")
        check(m.values(4, 2112, 1, fmt=":int"), [struct.unpack(">i", bytes.fromhex("DEADBEEF"))[0]],
              "DWORD 16#DEADBEEF as a signed 32-bit int")
        check(m.values(4, 2115, 1, zero_based=False, fmt=":float", conv=float), [1.0], "REAL 1.0 as reference 2115 (-B)")
        check(m.values(4, 2128, 2, fmt=":int"), [-2, 0x12345678], "DINT, UDINT copies")
        check(m.values(4, 2134, 1, fmt=":float", conv=float), [1.0], "REAL copy")
        # 64-bit values as their four registers (mbpoll has no 64-bit type).
        ml = m.values(4, 4216, 20, fmt=":hex", conv=hex_regs)
        want = []
        for fmt, v in ((">q", -3), (">Q", 0x0123456789ABCDEF), (">Q", 0xFEDCBA9876543210), (">d", 1.5),
                       (">q", 1_500_000_000)):
            want += list(struct.unpack(">HHHH", struct.pack(fmt, v)))
        check(ml, want, "LINT, ULINT, LWORD, LREAL, TIME as 20 registers, high word first")
        check(m.values(4, 4256, 20, fmt=":hex", conv=hex_regs), want, "their copies")

        # --- writes, seen in the read-only copies ------------------------------------------
        m.write(0, 0, [1], 1)                                   # FC 5
        m.wait(0, 1, 1, [1], "coil 1 (q_echo) after mbpoll wrote coil 0")
        m.wait(1, 1, 1, [1], "discrete input 1 (i_echo) after mbpoll wrote coil 0")
        pattern = [1, 1, 0, 1, 0, 0, 0, 1, 1, 0]
        m.write(0, 8, pattern, 10)                              # FC 15
        m.wait(1, 8, 10, pattern, "discrete inputs 8..17 after mbpoll wrote coils 8..17")
        m.write(4, 4, [65531], 1)                               # FC 6: INT -5
        m.wait(4, 10, 1, [65531], "holding 10 after mbpoll wrote INT -5 to 4")
        m.write(4, 5, [12345], 1)
        m.write(4, 6, [0x5A5A], 1)
        m.wait(3, 5, 1, [0x5A5A], "input register 5 (iw_echo) after mbpoll wrote WORD 6")
        m.wait(4, 11, 2, [12345, 0x5A5A], "holding 11..12 after mbpoll wrote 5 and 6")
        m.write(4, 1028, [5, 6, 7, 8], 4)                       # FC 16
        m.wait(4, 1038, 4, [5, 6, 7, 8], "array copy after mbpoll wrote 1028..1031")
        m.write(4, 1024, [65535, 1, 2], 3)
        m.wait(4, 1034, 3, [65535, 1, 2], "holding 1034..1036 after mbpoll wrote 1024..1026")
        m.write(4, 2108, [-123456, 3000000], 2, fmt=":int")      # 32-bit, high word first
        m.wait(4, 2128, 2, [-123456, 3000000], "DINT, UDINT copies after mbpoll -t 4:int -B", fmt=":int")
        m.write(4, 2114, [-2.5], 1, fmt=":float")
        m.wait(4, 2134, 1, [-2.5], "REAL copy after mbpoll -t 4:float -B", fmt=":float", conv=float)
        regs = list(struct.unpack(">HHHH", struct.pack(">d", -0.75)))
        m.write(4, 4228, regs, 1)                                # an LREAL as its four registers
        m.wait(4, 4268, 4, regs, "LREAL copy after mbpoll wrote 4 registers", fmt=":hex", conv=hex_regs)

        # --- exceptions as mbpoll reports them ---------------------------------------------
        m.fails(["-t", "4", "-r", "2115", "-0"], (), 0x02, "Illegal data address")   # half a REAL
        m.fails(["-t", "4", "-r", "10", "-0"], [1], 0x02, "Illegal data address")   # read-only copy
        m.fails(["-t", "4", "-r", "1027", "-0"], (), 0x02, "Illegal data address")  # unmapped
        m.fails(["-t", "0", "-r", "1", "-0"], [1], 0x02, "Illegal data address")    # read-only coil
        m.fails(["-a", "7", "-t", "4", "-r", "4", "-0"], (), 0x0B, "Target device failed to respond")
        check(m.values(4, 4, 1), [65531], "holding 4 after the refused requests")
    finally:
        counters = server.stop()
    P.check_counters(counters, tally)
    print("test_mbpoll: OK (%d mbpoll runs)" % tally.accepted)


if __name__ == "__main__":
    sys.exit(main())
