"""The HTTP server's bounds (docs/http-api.md, "Limits") against a real
`syncplc run --http 127.0.0.1:0`, from raw sockets: whatever a client sends,
the PLC's resident memory stays within BOUND of what it was, each attack
gets its clear 4xx, a request's framing is never ambiguous (one valid
Content-Length or a 400), and a flood of idle HTTP connections leaves the
Modbus server and a modbus_client driver their file descriptors.

  /usr/bin/python3 tests/peers/test_http_limits.py build/syncplc

Memory is watched while each attack is sent (every MiB): past the bound the
PLC is killed and the test fails at once, so a server without the bounds
costs the machine little more than the bound.
"""
import os
import resource
import select
import signal
import socket
import struct
import sys
import tempfile
import time
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib as P  # noqa: E402

BINARY = P.syncplc_binary()
MiB = 1 << 20
BOUND = 64 * MiB
# Hang guards only: every wait below ends on its condition.
ANSWER_TIMEOUT = 60.0
# The descriptor limit the PLC gets (soft = hard: nothing to raise to),
# and the idle connections that must not exhaust it.
NOFILE = 1024
IDLE_CONNECTIONS = 1100

PROJECT = """
project: {{name: http_limits, version: 1.0.0}}
tasks: [{{name: main, period: 10ms}}]
tags:
  - {{name: cmd, type: INT, init: 5, address: "%QW0", hmi: read}}
  - {{name: w_ok, type: BOOL}}
drivers:
  - name: io
    type: modbus_client
    devices: [{{name: dev, port: {port}, response_timeout: 200ms, connect_timeout: 200ms, reconnect_min: 20ms,
               reconnect_max: 200ms}}]
    groups:
      - {{name: w, function: write_single_register, address: 0, every: 20ms}}
    bind: {{w: cmd, w_ok: w_ok}}
"""


def status_field(pid, field):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024
    raise AssertionError("no %s in /proc/%d/status" % (field, pid))


class Plc:
    def __init__(self, project_file):
        # The PLC runs with at most NOFILE descriptors, soft and hard: its
        # own share for HTTP connections must leave Modbus theirs.
        def limit():
            resource.setrlimit(resource.RLIMIT_NOFILE, (NOFILE, NOFILE))
        self.srv = P.Server(BINARY, project_file, extra=["--http", "127.0.0.1:0", "--db", ":memory:"], preexec_fn=limit)
        self.pid = self.srv.proc.pid
        self.port = self.srv.http_port()

    def rss(self):
        return status_field(self.pid, "VmRSS")

    def kill(self):
        if self.srv.proc.poll() is None:
            self.srv.proc.send_signal(signal.SIGKILL)
            self.srv.proc.wait(timeout=30)


def read_answer(s, plc, start_rss, what):
    """The answer's status line and body (up to the end of its Content-Length),
    watching the PLC's memory while it comes."""
    data = b""
    deadline = time.monotonic() + ANSWER_TIMEOUT
    while time.monotonic() < deadline:
        grown = plc.rss() - start_rss
        if grown > BOUND:
            plc.kill()
            raise AssertionError("%s: the PLC's resident memory grew by %d MiB (bound %d MiB)"
                                 % (what, grown // MiB, BOUND // MiB))
        r, _, _ = select.select([s], [], [], 0.01)
        if not r:
            continue
        try:
            chunk = s.recv(65536)
        except ConnectionResetError:
            chunk = b""
        if not chunk:
            break
        data += chunk
        head, sep, body = data.partition(b"\r\n\r\n")
        if sep:
            length = 0
            for line in head.split(b"\r\n")[1:]:
                name, _, value = line.partition(b":")
                if name.strip().lower() == b"content-length":
                    length = int(value)
            if len(body) >= length:
                break
    if not data:
        raise AssertionError("%s: the connection ended without an answer" % what)
    line = data.split(b"\r\n", 1)[0].decode("latin-1")
    parts = line.split(" ", 2)
    if len(parts) < 2 or not parts[0].startswith("HTTP/1."):
        raise AssertionError("%s: not an HTTP answer: %r" % (what, data[:200]))
    return int(parts[1]), data.partition(b"\r\n\r\n")[2].decode("utf-8", "replace")


# One part only (to see each fail on a server without the bounds): "memory",
# "descriptors", or a word of one check's name ("gzip", "Content-Length").
ONLY = os.environ.get("SYNCPLC_HTTP_LIMITS_ONLY", "")


def chosen(what):
    return ONLY in ("", "memory") or ONLY in what


def attack(plc, what, head, pieces, want):
    """Sends head then each piece (stopping when an answer is there or the
    PLC closes), watching the PLC's memory after every piece; the answer
    must be `want`, with a JSON error saying why."""
    if not chosen(what):
        return
    s = socket.create_connection(("127.0.0.1", plc.port), timeout=ANSWER_TIMEOUT)
    start = plc.rss()
    sent = 0
    try:
        s.sendall(head)
        sent += len(head)
        for piece in pieces:
            r, _, _ = select.select([s], [], [], 0)
            if r:
                break
            grown = plc.rss() - start
            if grown > BOUND:
                plc.kill()
                raise AssertionError("%s: after %d MiB sent the PLC's resident memory grew by %d MiB (bound %d MiB)"
                                     % (what, sent // MiB, grown // MiB, BOUND // MiB))
            s.sendall(piece)
            sent += len(piece)
    except (BrokenPipeError, ConnectionResetError):
        pass  # closed by the PLC after its answer: read it
    status, body = read_answer(s, plc, start, what)
    s.close()
    peak = plc.rss() - start
    if status != want or '"error"' not in body:
        raise AssertionError("%s: expected %d with an error, got %d %r" % (what, want, status, body[:300]))
    if peak > BOUND:
        raise AssertionError("%s: the PLC's resident memory grew by %d MiB" % (what, peak // MiB))
    print("%s: %d after %d MiB sent, resident memory %+.1f MiB (%s)"
          % (what, status, sent // MiB, peak / MiB, body.strip()[:100]))


def repeat(piece, total):
    for _ in range(total // len(piece)):
        yield piece


def gzip_bomb(inflated):
    """A gzip body of about 500 KB that inflates to `inflated` bytes, made
    without ever holding the inflated bytes."""
    z = zlib.compressobj(9, zlib.DEFLATED, 31)
    zeros = b"\0" * MiB
    out = [z.compress(zeros) for _ in range(inflated // MiB)]
    out.append(z.flush())
    return b"".join(out)


def memory_and_framing(plc):
    host = b"Host: 127.0.0.1\r\n"
    login = b"POST /api/v1/login HTTP/1.1\r\n" + host + b"Content-Type: application/json\r\n"
    chunk = b"%x\r\n" % MiB + b"x" * MiB + b"\r\n"
    attack(plc, "600 MiB chunked body", login + b"Transfer-Encoding: chunked\r\n\r\n", repeat(chunk, 600 * len(chunk)), 413)
    attack(plc, "600 MiB body without Content-Length", login + b"\r\n", repeat(b"x" * MiB, 600 * MiB), 411)
    bomb = gzip_bomb(500 * MiB) if chosen("gzip") else b""
    assert len(bomb) < 600_000, len(bomb)  # the 510 KB
    attack(plc, "%d KB gzip body" % (len(bomb) // 1000),
           login + b"Content-Encoding: gzip\r\nContent-Length: %d\r\n\r\n" % len(bomb), [bomb[i:i + MiB] for i in range(0, len(bomb), MiB)], 415)
    attack(plc, "300 MiB request line", b"GET /", repeat(b"a" * MiB, 300 * MiB), 414)
    attack(plc, "200 MiB of header lines", b"GET /api/v1/status HTTP/1.1\r\n" + host,
           repeat((b"X-Filler: " + b"y" * 1000 + b"\r\n") * 1000, 200 * MiB), 431)
    # One length, stated once: anything else is a 400, never a guess (a
    # proxy in front that read the other framing would pass a second request
    # hidden in the body). POST /logout answers 200 to any well-framed request.
    logout = b"POST /api/v1/logout HTTP/1.1\r\n" + host + b"Content-Type: application/json\r\n"
    for name, fields in [("duplicate Content-Length", b"Content-Length: 2\r\nContent-Length: 2\r\n"),
                         ("two different Content-Lengths", b"Content-Length: 2\r\nContent-Length: 40\r\n"),
                         ("Content-Length: abc", b"Content-Length: abc\r\n"),
                         ("Content-Length with Transfer-Encoding", b"Content-Length: 2\r\nTransfer-Encoding: chunked\r\n")]:
        # The smuggled second request must never be answered: one answer, a 400, then the end.
        if not chosen(name):
            continue
        smuggled = b"GET /api/v1/status HTTP/1.1\r\n" + host + b"\r\n"
        s = socket.create_connection(("127.0.0.1", plc.port), timeout=ANSWER_TIMEOUT)
        s.sendall(logout + fields + b"\r\n{}" + smuggled)
        status, body = read_answer(s, plc, plc.rss(), name)
        rest = b""
        while True:
            try:
                k = s.recv(65536)
            except ConnectionResetError:
                break
            if not k:
                break
            rest += k
        s.close()
        if status != 400 or '"error"' not in body or b"HTTP/1." in rest:
            raise AssertionError("%s: expected one 400 and the end, got %d %r, then %r" % (name, status, body, rest[:200]))
        print("%s: 400 (%s)" % (name, body.strip()[:100]))


def modbus_served(port, unit, what):
    s = P.connect(port, timeout=20)
    # FC 3, register 0: cmd (%QW0).
    pdu = P.transact(s, P.mbap(7, unit, struct.pack(">BHH", 3, 0, 1)))
    s.close()
    if pdu != struct.pack(">BBH", 3, 2, 5):
        raise AssertionError("%s: a new Modbus client read %s" % (what, pdu.hex(" ")))


def descriptors(plc):
    try:
        resource.setrlimit(resource.RLIMIT_NOFILE, (resource.getrlimit(resource.RLIMIT_NOFILE)[1],) * 2)
    except ValueError:
        pass
    soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    if soft < IDLE_CONNECTIONS + 200:
        raise AssertionError("this script needs %d descriptors (ulimit -Hn is %d)" % (IDLE_CONNECTIONS + 200, soft))
    dev = DEVICE
    P.wait_until(lambda: (dev.registers[0] == 5, dev.registers[0]), "the driver writes cmd before the flood", timeout=20)
    idle = []

    def top_up():
        # Keep IDLE_CONNECTIONS open: one the PLC closed (refused, or cut
        # as idle) is opened again.
        alive = []
        for c in idle:
            try:
                if c.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b"":
                    c.close()
                    continue
            except BlockingIOError:
                pass
            except OSError:
                c.close()
                continue
            alive.append(c)
        idle[:] = alive
        while len(idle) < IDLE_CONNECTIONS:
            c = socket.socket()
            c.settimeout(5)
            try:
                c.connect(("127.0.0.1", plc.port))
            except OSError:
                c.close()
                continue
            idle.append(c)

    top_up()
    # The HTTP server keeps to its share: descriptors stay free for the rest.
    open_fds = len(os.listdir("/proc/%d/fd" % plc.pid))
    print("%d idle HTTP connections: the PLC holds %d descriptors of %d" % (IDLE_CONNECTIONS, open_fds, NOFILE))
    if open_fds > NOFILE - 64:
        raise AssertionError("the PLC holds %d of its %d descriptors during the flood" % (open_fds, NOFILE))
    # A new Modbus TCP client is served beside them.
    top_up()
    t0 = time.monotonic()
    modbus_served(plc.srv.port, plc.srv.unit, "beside %d idle HTTP connections" % IDLE_CONNECTIONS)
    print("a new Modbus client connected and read in %.1f ms" % ((time.monotonic() - t0) * 1e3))
    # The device drops the driver's connection: the driver connects again
    # (a new socket, a new descriptor) and writes cmd again.
    top_up()
    accepted = dev.accepted
    dev.registers[0] = 0
    dev.active.shutdown(socket.SHUT_RDWR)
    P.wait_until(lambda: (dev.accepted > accepted and dev.registers[0] == 5, (dev.accepted, dev.registers[0])),
                 "the modbus_client driver reconnects beside %d idle HTTP connections" % IDLE_CONNECTIONS, timeout=20)
    top_up()
    open_fds = len(os.listdir("/proc/%d/fd" % plc.pid))
    if open_fds > NOFILE - 64:
        raise AssertionError("the PLC holds %d of its %d descriptors during the flood" % (open_fds, NOFILE))
    for c in idle:
        c.close()
    # The flood gone, HTTP answers again.
    P.wait_until(lambda: (lambda s: (s == 200, s))(http_status(plc.port)), "GET /api/v1/status after the flood", timeout=30)
    print("modbus client served and driver reconnected beside the flood; HTTP answers after it")


def http_status(port):
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=5)
        s.sendall(b"GET /api/v1/status HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")
        line = s.recv(64)
        s.close()
        return int(line.split()[1]) if line.startswith(b"HTTP/1.") else 0
    except OSError:
        return 0


DEVICE = None


def main():
    global DEVICE
    DEVICE = P.OneConnectionDevice()
    with tempfile.TemporaryDirectory() as d:
        project = os.path.join(d, "http_limits.yaml")
        with open(project, "w") as f:
            f.write(PROJECT.format(port=DEVICE.port))
        plc = Plc(project)
        try:
            if ONLY != "descriptors":
                memory_and_framing(plc)
            if ONLY in ("", "descriptors"):
                descriptors(plc)
        except BaseException:
            plc.kill()
            raise
        plc.srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
