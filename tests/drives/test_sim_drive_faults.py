"""Fault injection of the simulated CiA 402 drive, each observed from the
client side: dropped connections (and the reconnect), a drive that accepts
and stays silent, every kind of malformed reply, a drive fault in the
statusword and 603Fh, and requests to another unit id (no answer).

    /usr/bin/python3 tests/drives/test_sim_drive_faults.py
"""

import signal
import socket
import struct
import time

from drivelib import Axis, SimDrive, check, decode, raw_request, sim

READ_IR = bytes([0x04]) + struct.pack(">HH", 0, sim.IR_COUNT)   # FC 4, 12 registers
READ_HR = bytes([0x03]) + struct.pack(">HH", 0, 4)              # FC 3, 4 registers


def good_reply(data, tid=0x1234, unit=1, fc=0x04, count=sim.IR_COUNT):
    if len(data) != 9 + 2 * count:
        return False
    t, proto, length, u, f, n = struct.unpack(">HHHBBB", data[:9])
    return t == tid and proto == 0 and length == 3 + 2 * count and u == unit and f == fc and n == 2 * count


def main():
    d = SimDrive()
    a = Axis(d.port)
    a.enable(8)
    check(good_reply(raw_request(d.port, READ_IR)), "a raw FC 4 request gets a well-formed reply")

    # drop: every connection closed at once; the drive runs on, a new one works.
    s = socket.create_connection(("127.0.0.1", d.port), timeout=2)
    time.sleep(0.05)
    d.ok("drop")
    s.settimeout(2)
    check(s.recv(100) == b"", "drop: the open connection is closed by the drive")
    s.close()
    try:
        r = a.c.read_input_registers(0, 2, slave=1)
        failed = r.isError()
    except Exception:  # pymodbus raises ConnectionException on a closed socket
        failed = True
    check(failed, "drop: the pymodbus client's request on the dropped connection fails")
    a.close()
    a = Axis(d.port)
    check(decode(a.actual()["statusword"]) == sim.OPERATION_ENABLED,
          "drop: reconnected, the drive kept its state (Operation enabled)")

    # silent: connections are accepted, requests are never answered.
    d.ok("silent on")
    t0 = time.monotonic()
    data = raw_request(d.port, READ_IR, timeout=0.5, reply=False)
    check(data == b"" and time.monotonic() - t0 >= 0.45, "silent: connected, no reply in 0.5 s")
    with socket.create_connection(("127.0.0.1", d.port), timeout=0.5) as s2:
        s2.sendall(struct.pack(">HHHB", 7, 0, len(READ_HR) + 1, 1) + READ_HR)
        try:
            got = s2.recv(100)
            check(False, "silent: unexpected %r" % got)
        except socket.timeout:
            check(True, "silent: the connection stays open and quiet")
    d.ok("silent off")
    check(good_reply(raw_request(d.port, READ_IR)), "silent off: answered again")

    # delay: the next COUNT replies leave late, whole and in order; then on time again.
    d.ok("delay 300 2")
    with socket.create_connection(("127.0.0.1", d.port), timeout=5) as s3:
        for tid in (21, 22, 23):
            t0 = time.monotonic()
            s3.sendall(struct.pack(">HHHB", tid, 0, len(READ_IR) + 1, 1) + READ_IR)
            data = b""
            while len(data) < 9 + 2 * sim.IR_COUNT:
                chunk = s3.recv(4096)
                check(chunk != b"", "delay: the connection stays open")
                data += chunk
            took = time.monotonic() - t0
            check(good_reply(data, tid=tid), "delay: reply %d well formed" % tid)
            if tid < 23:
                check(took >= 0.29, "delay: reply %d held back 300 ms (%.3f s)" % (tid, took))
    with socket.create_connection(("127.0.0.1", d.port), timeout=5) as s4:
        s4.sendall(struct.pack(">HHHB", 24, 0, len(READ_IR) + 1, 1) + READ_IR)
        check(good_reply(s4.recv(4096), tid=24), "delay: used up after COUNT replies")
    # a delayed reply whose connection closed meanwhile is dropped; the drive serves on
    d.ok("delay 200")
    check(raw_request(d.port, READ_IR, timeout=0.05, reply=False) == b"", "delay: nothing within 50 ms")
    time.sleep(0.3)
    check(good_reply(raw_request(d.port, READ_IR)), "delay: the drive answers the next connection")
    check(d.command("delay 0") .startswith("error"), "delay 0 is refused")

    # garbage: one malformed reply per mode.
    expect = {
        "tid": lambda r: len(r) == 9 + 24 and struct.unpack(">H", r[:2])[0] == 0x1235,
        "unit": lambda r: len(r) == 9 + 24 and r[6] == 2,
        "function": lambda r: len(r) == 9 + 24 and r[7] == 0x03,
        "length": lambda r: len(r) == 9 + 24 and struct.unpack(">H", r[4:6])[0] == 3 + 24 + 4,
        "short": lambda r: len(r) == 9 + 24 and r[8] == 26,
        "oversized": lambda r: len(r) == 9 + 600 and r[8] == 250,
        "exception": lambda r: r[7:] == bytes([0x84, 0x06]),
        "bytes": lambda r: len(r) == 9 + 24 and not good_reply(r),
    }
    for mode, ok in expect.items():
        d.ok("garbage " + mode)
        r = raw_request(d.port, READ_IR, timeout=0.3)
        check(ok(r), "garbage %s: %s" % (mode, r[:12].hex()))
    d.ok("garbage off")
    check(good_reply(raw_request(d.port, READ_IR)), "garbage off: well-formed again")
    # pymodbus's own client on an exception reply: an error, not a value.
    # (Its 3.0 client takes a reply with a wrong transaction id as valid:
    # checking that is the Modbus client driver's job, not this drive's.)
    d.ok("garbage exception")
    r = a.c.read_input_registers(0, 2, slave=1)
    check(r.isError(), "garbage exception: pymodbus reports %s" % r)
    d.ok("garbage off")
    a.close()
    a = Axis(d.port)

    # A drive fault: the statusword's fault bit and 603Fh.
    d.ok("fault 0x2310")
    sw = a.wait_state(sim.FAULT)
    check(sw & 0x08 and a.actual()["error_code"] == 0x2310, "fault: bit 3 set, error code 16#2310")

    # Another unit id: pymodbus ignores it (no reply, as a gateway without the device).
    check(raw_request(d.port, READ_IR, unit=7, timeout=0.3, reply=False) == b"", "unit 7: no reply")
    check(good_reply(raw_request(d.port, READ_IR, unit=1)), "unit 1 answered")

    # The mirror of the input registers in holding registers 100..: FC 23
    # writes the controlword and reads the actual values in one exchange.
    a.controlword(0x00)
    time.sleep(0.01)
    r = a.c.readwrite_registers(read_address=sim.MIRROR, read_count=sim.IR_COUNT,
                                write_address=sim.HR_CONTROLWORD, write_registers=[0x80], unit=1)
    check(not r.isError() and len(r.registers) == sim.IR_COUNT, "FC 23 on the mirror")
    a.wait_state(sim.SWITCH_ON_DISABLED)
    r = a.c.readwrite_registers(read_address=sim.MIRROR, read_count=sim.IR_COUNT,
                                write_address=sim.HR_CONTROLWORD, write_registers=[0x00], unit=1)
    check(decode(r.registers[sim.IR_STATUSWORD]) == sim.SWITCH_ON_DISABLED, "FC 23: the reset took, mirror reads it")
    a.close()
    check(d.stop() == 0, "SIGTERM: clean stop")

    # Without a pipe: the control socket, SIGUSR1 (drop), SIGUSR2 (silent on/off).
    d = SimDrive("--control-port", "0")
    with socket.create_connection(("127.0.0.1", d.control_port), timeout=5) as ctl:
        f = ctl.makefile("rw")
        f.write("silent on\n")
        f.flush()
        check(f.readline().strip() == "ok silent on", "control socket: ok silent on")
        check(raw_request(d.port, READ_IR, timeout=0.3, reply=False) == b"", "control socket: silent took effect")
        f.write("silent off\nstatus\nnonsense\n")
        f.flush()
        check(f.readline().strip() == "ok silent off", "control socket: ok silent off")
        check(f.readline().startswith("status {"), "control socket: status")
        check(f.readline().startswith("error"), "control socket: an unknown command is refused")
    check(good_reply(raw_request(d.port, READ_IR)), "answered again")
    s = socket.create_connection(("127.0.0.1", d.port), timeout=2)
    time.sleep(0.05)
    d.p.send_signal(signal.SIGUSR1)
    check(s.recv(100) == b"", "SIGUSR1: connections dropped")
    s.close()
    d.p.send_signal(signal.SIGUSR2)
    time.sleep(0.1)
    check(raw_request(d.port, READ_IR, timeout=0.3, reply=False) == b"", "SIGUSR2: silent")
    d.p.send_signal(signal.SIGUSR2)
    time.sleep(0.1)
    check(good_reply(raw_request(d.port, READ_IR)), "SIGUSR2 again: answering")
    check(d.stop() == 0, "SIGTERM: clean stop")


if __name__ == "__main__":
    main()
