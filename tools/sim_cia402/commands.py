"""The fault-injection commands (tools/sim_cia402_drive.py's docstring),
from stdin and from the control socket."""

import asyncio
import json
import sys

from .faults import GARBAGE_MODES, Faults


def say(text):
    sys.stdout.write(text + "\n")
    sys.stdout.flush()


def command(line, drive, loop, server, stop):
    """Runs one fault-injection command; returns the answer line ("" for
    an empty line). Called from the stdin thread and the control socket."""
    words = line.split()
    if not words:
        return ""
    cmd, args = words[0], words[1:]
    try:
        if cmd == "drop":
            def drop():
                for handler in list(server.active_connections.values()):
                    handler.transport.abort()
            loop.call_soon_threadsafe(drop)
        elif cmd == "silent" and args in (["on"], ["off"]):
            Faults.silent = args[0] == "on"
        elif cmd == "garbage" and len(args) == 1 and (args[0] in GARBAGE_MODES or args[0] == "off"):
            Faults.garbage = None if args[0] == "off" else args[0]
        elif cmd == "delay" and 1 <= len(args) <= 2:
            ms, count = float(args[0]), int(args[1]) if len(args) == 2 else 1
            if not (0 < ms <= 60000 and count > 0):
                raise ValueError("delay MS [COUNT]: 0 < MS <= 60000, COUNT > 0")
            Faults.delay_s, Faults.delayed_left = ms / 1000.0, count
        elif cmd == "fault" and args == ["clear"]:
            drive.clear_persistent()
        elif cmd == "fault" and 1 <= len(args) <= 2 and (len(args) == 1 or args[1] == "persist"):
            code = int(args[0], 0)
            if not 0 < code <= 0xFFFF:
                raise ValueError("error code must be 1..0xFFFF")
            drive.inject_fault(code, len(args) == 2)
        elif cmd == "status":
            return "status " + json.dumps(drive.status())
        elif cmd == "quit":
            stop.set()
        else:
            return "error unknown command: " + line.strip()
        return "ok " + " ".join(words)
    except ValueError as e:
        return "error %s: %s" % (line.strip(), e)


def read_commands(drive, loop, server, stop):
    for line in sys.stdin:
        answer = command(line, drive, loop, server, stop)
        if answer:
            say(answer)
        if stop.is_set():
            break
    # stdin closed: keep running (a drive started without a terminal)


async def control_client(reader, writer, drive, loop, server, stop):
    """The control socket: the stdin commands, one per line, answered on the socket."""
    try:
        while not stop.is_set():
            line = await reader.readline()
            if not line:
                break
            answer = command(line.decode("utf-8", "replace"), drive, loop, server, stop)
            if answer:
                writer.write((answer + "\n").encode())
                await writer.drain()
    except (ConnectionError, asyncio.CancelledError):
        pass
    finally:
        writer.close()
