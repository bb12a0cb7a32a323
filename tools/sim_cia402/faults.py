"""Injected reply faults: a silent drive, malformed replies of every kind,
late replies, on pymodbus's connection handler."""

import asyncio
import random
import struct

from pymodbus.server.async_io import ModbusConnectedRequestHandler


class Faults:
    """What the server does to its replies; set by the command thread."""
    silent = False
    garbage = None  # None or a mode
    # `delay MS [COUNT]`: the next COUNT replies leave MS ms late (a drive
    # that stalls: its master's response timeout decides what that costs)
    delay_s = 0.0
    delayed_left = 0


GARBAGE_MODES = ("bytes", "tid", "unit", "function", "length", "short", "oversized", "exception")


def malformed(frame, mode):
    """A reply that breaks the Modbus TCP rules in one way (MBAP header:
    transaction id, protocol 0, length, unit; then the PDU)."""
    tid, proto, length, unit = struct.unpack(">HHHB", frame[:7])
    pdu = frame[7:]
    fc = pdu[0]
    if mode == "bytes":
        return bytes(random.getrandbits(8) for _ in range(len(frame)))
    if mode == "tid":
        return struct.pack(">HHHB", (tid + 1) & 0xFFFF, proto, length, unit) + pdu
    if mode == "unit":
        return struct.pack(">HHHB", tid, proto, length, (unit + 1) & 0xFF) + pdu
    if mode == "function":
        other = 0x04 if fc == 0x03 else 0x03
        return struct.pack(">HHHB", tid, proto, length, unit) + bytes([other]) + pdu[1:]
    if mode == "length":  # the header claims 4 more bytes than follow
        return struct.pack(">HHHB", tid, proto, length + 4, unit) + pdu
    if mode == "short":   # the byte count says more registers than the reply holds
        if fc in (3, 4, 23) and len(pdu) > 3:
            body = bytes([fc, pdu[1] + 2]) + pdu[2:]
            return struct.pack(">HHHB", tid, proto, len(body) + 1, unit) + body
        return frame[:-1]
    if mode == "oversized":  # 300 registers: beyond the 125 a reply may carry (260-byte ADU)
        body = bytes([fc, 250]) + bytes(600)
        return struct.pack(">HHHB", tid, proto, len(body) + 1, unit) + body
    if mode == "exception":  # server device busy (06h) for every request
        return struct.pack(">HHHB", tid, proto, 3, unit) + bytes([fc | 0x80, 0x06])
    return frame


class FaultyHandler(ModbusConnectedRequestHandler):
    """pymodbus's connection handler with the injected reply faults; every
    request to the drive's unit marks the master alive (`liveness`, set by
    main.py: the drive's 6007h reaction, state_machine.py)."""

    liveness = None
    unit = None

    def execute(self, request, *addr):
        if self.liveness is not None and request.unit_id == self.unit:
            self.liveness.seen()
        super().execute(request, *addr)

    def send(self, message, *addr, **kwargs):
        if Faults.silent:
            return
        if Faults.delayed_left > 0 and message.should_respond:
            Faults.delayed_left -= 1
            # on the server's loop (this is its thread): the reply is sent
            # later on the same connection, or dropped if it closed meanwhile
            asyncio.get_running_loop().call_later(Faults.delay_s, self._late_send, message, addr, kwargs)
            return
        self._send_now(message, addr, kwargs)

    def _send_now(self, message, addr, kwargs):
        mode = Faults.garbage
        if mode is None or kwargs.get("skip_encoding") or not message.should_respond:
            super().send(message, *addr, **kwargs)
            return
        self._send_(malformed(self.framer.buildPacket(message), mode))

    def _late_send(self, message, addr, kwargs):
        if self.transport is None or self.transport.is_closing():
            return
        if not Faults.silent:
            self._send_now(message, addr, kwargs)
