"""What the Modbus peer tests share: start and stop `syncplc run`, count what
the script did, compare it with the counters the server prints, and talk
raw Modbus TCP over a plain socket where a well-behaved client cannot.

Run the tests with Debian's interpreter, the only one that sees
python3-pymodbus:  /usr/bin/python3 tests/peers/test_X.py build/syncplc
"""

import atexit
import http.client
import json
import os
import random
import re
import select
import signal
import socket
import struct
import shutil
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))

# How long a write may take to show in its read-only copy: it is applied at
# the start of the owning task's next scan (2 ms here), but a sanitizer build
# on a loaded 2-core machine can be much slower. Only a guard against a hang:
# every wait_until waits for a condition.
ECHO_TIMEOUT = 60.0
# Safety net: a syncplc the script forgot (or could not stop) ends by itself.
RUN_LIMIT = "280s"

# Each test script gives the `syncplc run`s it starts a PLC database of its
# own (they inherit XDG_STATE_HOME): ctest runs the scripts in parallel, and a
# second instance on one database is refused.
STATE_DIR = tempfile.mkdtemp(prefix="syncplc-state-")
os.environ["XDG_STATE_HOME"] = STATE_DIR
atexit.register(shutil.rmtree, STATE_DIR, True)

_running = []


def _kill_leftovers():
    for p in _running:
        if p.poll() is None:
            p.kill()


atexit.register(_kill_leftovers)


def syncplc_binary():
    if len(sys.argv) < 2:
        sys.exit("usage: /usr/bin/python3 %s PATH/TO/syncplc" % sys.argv[0])
    path = sys.argv[1]
    if not os.access(path, os.X_OK):
        sys.exit("not an executable: %s" % path)
    return path


def project(name):
    return os.path.join(HERE, name)


class Counters:
    """The server's statistics block, as `syncplc run` prints it on stdout."""

    LINE1 = re.compile(r"requests (\d+), exceptions (\d+)(?: \(([^)]*)\))?, values written (\d+)")
    LINE2 = re.compile(r"connections: (\d+) accepted, (\d+) refused, (\d+) open; closed: (\d+) by the client, "
                       r"(\d+) bad frame, (\d+) idle, (\d+) not reading")

    def __init__(self, text):
        m1 = self.LINE1.search(text)
        m2 = self.LINE2.search(text)
        if not m1 or not m2 or "Modbus TCP on 127.0.0.1:" not in text:
            raise AssertionError("no Modbus statistics in the output of syncplc run:\n" + text)
        self.requests = int(m1.group(1))
        self.exceptions = int(m1.group(2))
        self.by_code = {}
        if m1.group(3):
            for part in m1.group(3).split(","):
                code, n = part.split(":")
                self.by_code[int(code.strip(), 16)] = int(n)
        self.values_written = int(m1.group(4))
        (self.accepted, self.refused, self.open, self.closed_by_client, self.closed_bad_frame, self.closed_idle,
         self.closed_not_reading) = (int(g) for g in m2.groups())
        self.text = text

    def __repr__(self):
        return "Counters(%s)" % ", ".join("%s=%r" % kv for kv in sorted(vars(self).items()) if kv[0] != "text")


class Tally:
    """What the script did, to be compared with the server's counters."""

    def __init__(self):
        self.requests = 0
        self.by_code = {}
        self.values_written = 0
        self.accepted = 0
        self.refused = 0
        self.closed_bad_frame = 0
        self.closed_idle = 0
        self.closed_not_reading = 0
        self.lock = threading.Lock()

    def ok(self, n=1, written=0):
        with self.lock:
            self.requests += n
            self.values_written += written

    def exception(self, code, n=1):
        with self.lock:
            self.requests += n
            self.by_code[code] = self.by_code.get(code, 0) + n

    def connection(self, n=1):
        with self.lock:
            self.accepted += n

    @property
    def exceptions(self):
        return sum(self.by_code.values())


class Server:
    """`syncplc run PROJECT --no-status --modbus-port 0`, stopped with SIGTERM."""

    def __init__(self, binary, project_file, extra=(), preexec_fn=None):
        self.binary = binary
        self.project_file = project_file
        self.stderr_lines = []
        args = [binary, "run", project_file, "--no-status", "--modbus-port", "0", "-d", RUN_LIMIT, *extra]
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=preexec_fn)
        _running.append(self.proc)
        self.port = None
        self.unit = None
        self.mapped = None
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            if not line:
                break
            self.stderr_lines.append(line)
            m = re.search(r"modbus: listening on 127\.0\.0\.1:(\d+) \(unit (\d+), (\d+) values mapped\)", line)
            if m:
                self.port, self.unit, self.mapped = (int(g) for g in m.groups())
                break
        if self.port is None:
            self.proc.kill()
            out, err = self.proc.communicate()
            raise AssertionError("syncplc run %s did not report its Modbus port; stderr:\n%s%s\nstdout:\n%s"
                                 % (project_file, "".join(self.stderr_lines), err, out))
        self._drain = threading.Thread(target=self._read_stderr, daemon=True)
        self._drain.start()

    def http_port(self, scheme="http", timeout=30):
        """The port `run --http 127.0.0.1:0` chose, from the line it prints."""
        pattern = re.compile(r"HTTP API on %s://127\.0\.0\.1:(\d+)/" % scheme)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            for line in list(self.stderr_lines):
                m = pattern.search(line)
                if m:
                    return int(m.group(1))
            time.sleep(0.05)
        raise AssertionError("no %s address on the stderr of syncplc run:\n%s" % (scheme, "".join(self.stderr_lines)))

    def _read_stderr(self):
        for line in self.proc.stderr:
            self.stderr_lines.append(line)

    def stop(self):
        """SIGTERM; returns the counters it printed. It must exit with status 0."""
        self.proc.send_signal(signal.SIGTERM)
        try:
            out = self.proc.stdout.read()
            rc = self.proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise AssertionError("syncplc run did not stop within 60 s of SIGTERM")
        self._drain.join(timeout=10)
        self.stdout = out
        stderr = "".join(self.stderr_lines)
        if rc != 0:
            raise AssertionError("syncplc run exited with status %d\nstdout:\n%s\nstderr:\n%s" % (rc, out, stderr))
        if "Stopped by SIGTERM" not in out:
            raise AssertionError("syncplc run stopped before SIGTERM (the -d %s safety net?)\n%s" % (RUN_LIMIT, out))
        for bad in ("ERROR: AddressSanitizer", "runtime error:", "WARNING: ThreadSanitizer"):
            if bad in stderr:
                raise AssertionError("sanitizer report on stderr:\n" + stderr)
        return Counters(out)


class HttpApi:
    """The HTTP API of a `syncplc run --http`, from Python's own http.client:
    call() returns (status, JSON or None, response); expect() checks the
    status. `source`: the client's address (127.0.0.x: a machine of its own
    as the login limiter sees it); `token`: the session's bearer token."""

    def __init__(self, port, source="127.0.0.1", token=None):
        self.port = port
        self.source = source
        self.token = token

    def call(self, method, path, body=None, headers=None, raw=None, content_type="application/json", absolute=False,
             token=None):
        # An online change waits up to three periods of the slowest task.
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120 if path.startswith("/projects") else 30,
                                       source_address=(self.source, 0))
        h = dict(headers or {})
        tok = self.token if token is None else token
        if tok:
            h["Authorization"] = "Bearer " + tok
        data = raw if raw is not None else (json.dumps(body).encode() if body is not None else None)
        if data is not None:
            h.setdefault("Content-Type", content_type)
        c.request(method, path if absolute else "/api/v1" + path, body=data, headers=h)
        r = c.getresponse()
        text = r.read().decode("utf-8", "replace")
        c.close()
        try:
            j = json.loads(text) if text else None
        except ValueError:
            j = None
        return r.status, j, r

    def expect(self, status, method, path, body=None, what="", **kw):
        got, j, _ = self.call(method, path, body, **kw)
        if got != status:
            raise AssertionError("%s %s %s: expected HTTP %d, got %d %r" % (what, method, path, status, got, j))
        return j


def check_counters(c, t, requests_at_least=False, label=""):
    """Compare the server's counters with the script's tally; one message with every difference."""
    problems = []

    def same(what, got, want):
        if got != want:
            problems.append("%s: server says %r, the script did %r" % (what, got, want))

    if requests_at_least:
        if c.requests < t.requests:
            problems.append("requests: server says %d, the script sent at least %d" % (c.requests, t.requests))
    else:
        same("requests", c.requests, t.requests)
    same("exceptions by code", c.by_code, t.by_code)
    same("exceptions", c.exceptions, t.exceptions)
    same("values written", c.values_written, t.values_written)
    same("connections accepted", c.accepted, t.accepted)
    same("connections refused", c.refused, t.refused)
    same("closed for a bad frame", c.closed_bad_frame, t.closed_bad_frame)
    same("closed idle", c.closed_idle, t.closed_idle)
    same("closed not reading", c.closed_not_reading, t.closed_not_reading)
    # The scripts close every connection before they stop the server, but a
    # close the server has not read yet when SIGTERM arrives is still open for
    # it (it does not count connections it closes at shutdown as the client's).
    same("closed by the client or still open at the stop (the rest)", c.closed_by_client + c.open,
         c.accepted - c.closed_bad_frame - c.closed_idle - c.closed_not_reading)
    if problems:
        raise AssertionError("%scounters do not match:\n  %s\nserver output:\n%s"
                             % (label + ": " if label else "", "\n  ".join(problems), c.text))
    print("%scounters match: %r" % (label + ": " if label else "", c))


# --- pymodbus -----------------------------------------------------------------------

def add_user(binary, db, name, role, password):
    """`syncplc user add` into the database a server will use."""
    p = subprocess.run([binary, "user", "add", name, "--role", role, "--password-stdin", "--db", db],
                       input=password + "\n", text=True, capture_output=True, timeout=60)
    if p.returncode != 0:
        raise AssertionError("syncplc user add %s: %d\n%s%s" % (name, p.returncode, p.stdout, p.stderr))


def free_port():
    """A free 127.0.0.1 port below the kernel's ephemeral range. A port from
    that range (what bind(0) hands out) can be taken by a client of the test
    itself: a driver reconnecting to a device that is down may be given the
    device's own port as its source port and connect to itself (TCP
    simultaneous open), and the restarted device then cannot bind."""
    low = 32768
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
            low = int(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        pass
    rng = random.Random(os.getpid() ^ int(time.monotonic_ns()))
    for _ in range(200):
        port = rng.randrange(max(1024, low - 12000), low)
        s = socket.socket()
        try:
            s.bind(("127.0.0.1", port))
            return port
        except OSError:
            continue
        finally:
            s.close()
    raise AssertionError("no free port below %d" % low)


def pymodbus_client(port, timeout=5):
    from pymodbus.client import ModbusTcpClient  # only /usr/bin/python3 has it
    # retries=0: one request per call, so the script's count is the server's.
    c = ModbusTcpClient("127.0.0.1", port=port, timeout=timeout, retries=0, retry_on_empty=False)
    if not c.connect():
        raise AssertionError("pymodbus could not connect to 127.0.0.1:%d" % port)
    return c


def expect_ok(resp, what):
    if resp is None or not hasattr(resp, "isError") or resp.isError():
        raise AssertionError("%s: expected a normal response, got %r" % (what, resp))
    return resp


def expect_exception(resp, code, what):
    got = getattr(resp, "exception_code", None)
    if not (hasattr(resp, "isError") and resp.isError() and got == code):
        raise AssertionError("%s: expected exception %02X, got %r" % (what, code, resp))


def wait_until(fn, what, timeout=ECHO_TIMEOUT, interval=0.005):
    """Polls fn() until it returns a true value; returns (value, polls)."""
    deadline = time.monotonic() + timeout
    polls = 0
    last = None
    while True:
        polls += 1
        ok, last = fn()
        if ok:
            return last, polls
        if time.monotonic() > deadline:
            raise AssertionError("%s: still %r after %.1f s" % (what, last, timeout))
        time.sleep(interval)


# --- raw Modbus TCP -----------------------------------------------------------------

def mbap(tid, unit, pdu, protocol=0, length=None):
    return struct.pack(">HHHB", tid, protocol, len(pdu) + 1 if length is None else length, unit) + pdu


def connect(port, timeout=5.0):
    s = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def recv_exact(s, n):
    data = b""
    while len(data) < n:
        chunk = s.recv(n - len(data))
        if not chunk:
            raise AssertionError("connection closed after %d of %d bytes of a reply" % (len(data), n))
        data += chunk
    return data


def recv_reply(s):
    """One whole Modbus TCP reply: (tid, unit, pdu)."""
    head = recv_exact(s, 7)
    tid, proto, length, unit = struct.unpack(">HHHB", head)
    if proto != 0 or not 2 <= length <= 254:
        raise AssertionError("reply with protocol id %d, length %d" % (proto, length))
    return tid, unit, recv_exact(s, length - 1)


def transact(s, frame):
    s.sendall(frame)
    tid, unit, pdu = recv_reply(s)
    want_tid = struct.unpack(">H", frame[:2])[0]
    if tid != want_tid:
        raise AssertionError("reply has transaction id %d, the request %d" % (tid, want_tid))
    return pdu


def raw_exception(s, frame, code, what):
    pdu = transact(s, frame)
    fc = frame[7]
    if pdu != bytes([fc | 0x80, code]):
        raise AssertionError("%s: expected exception %02X (%02X %02X), got %s"
                             % (what, code, fc | 0x80, code, pdu.hex(" ")))


def closed_by_server(s, timeout=5.0):
    """True when the server closes the connection within timeout (EOF or reset)."""
    s.settimeout(timeout)
    try:
        data = s.recv(1024)
    except ConnectionResetError:
        return True
    except socket.timeout:
        return False
    if data:
        raise AssertionError("expected the connection to be closed, got %d bytes: %s" % (len(data), data.hex(" ")))
    return True


def refused(port, timeout=5.0):
    """Connects; True when the server closes the connection at once, before any request."""
    s = connect(port)
    try:
        return closed_by_server(s, timeout)
    finally:
        s.close()


def readable_soon(s, timeout):
    r, _, _ = select.select([s], [], [], timeout)
    return bool(r)


def run(args, **kw):
    return subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


# --- typed values <-> registers, with pymodbus's payload builder and decoder ----------

WIDTH = {"BOOL": 1, "SINT": 1, "USINT": 1, "BYTE": 1, "INT": 1, "UINT": 1, "WORD": 1,
         "DINT": 2, "UDINT": 2, "DWORD": 2, "REAL": 2,
         "LINT": 4, "ULINT": 4, "LWORD": 4, "LREAL": 4, "TIME": 4}
_CODEC = {"SINT": "16bit_int", "USINT": "16bit_uint", "BYTE": "16bit_uint", "INT": "16bit_int",
          "UINT": "16bit_uint", "WORD": "16bit_uint", "DINT": "32bit_int", "UDINT": "32bit_uint",
          "DWORD": "32bit_uint", "REAL": "32bit_float", "LINT": "64bit_int", "ULINT": "64bit_uint",
          "LWORD": "64bit_uint", "LREAL": "64bit_float", "TIME": "64bit_int"}


def _endian(word_order):
    from pymodbus.constants import Endian
    return {"high_first": Endian.Big, "low_first": Endian.Little}[word_order]


def encode(values, word_order="high_first"):
    """[(type, value), ...] -> registers, each big-endian, words in word_order."""
    from pymodbus.constants import Endian
    from pymodbus.payload import BinaryPayloadBuilder
    b = BinaryPayloadBuilder(byteorder=Endian.Big, wordorder=_endian(word_order))
    for t, v in values:
        getattr(b, "add_" + _CODEC[t])(v)
    return b.to_registers()


def decode(types, regs, word_order="high_first"):
    """registers -> [value, ...] of the given types."""
    from pymodbus.constants import Endian
    from pymodbus.payload import BinaryPayloadDecoder
    want = sum(WIDTH[t] for t in types)
    if len(regs) != want:
        raise AssertionError("%d registers for %s, expected %d" % (len(regs), types, want))
    d = BinaryPayloadDecoder.fromRegisters(list(regs), byteorder=Endian.Big, wordorder=_endian(word_order))
    return [getattr(d, "decode_" + _CODEC[t])() for t in types]


def same_value(t, a, b):
    """Equal as the tag stores them (REAL compared as float32 bit patterns)."""
    if t == "REAL":
        return struct.pack(">f", a) == struct.pack(">f", b)
    if t == "LREAL":
        return struct.pack(">d", a) == struct.pack(">d", b)
    return a == b


class Peer:
    """A pymodbus client that counts what it does into a Tally."""

    def __init__(self, port, tally, unit=1, timeout=5):
        self.c = pymodbus_client(port, timeout)
        self.tally = tally
        self.unit = unit
        tally.connection()

    def close(self):
        self.c.close()

    def _call(self, name, *args, **kw):
        kw.setdefault("slave", self.unit)
        return getattr(self.c, name)(*args, **kw)

    _READ = {"coil": "read_coils", "discrete": "read_discrete_inputs",
             "input": "read_input_registers", "holding": "read_holding_registers"}

    def read(self, table, address, count, **kw):
        r = self._call(self._READ[table], address, count, **kw)
        expect_ok(r, "read %s %d..%d" % (table, address, address + count - 1))
        self.tally.ok()
        if table in ("coil", "discrete"):
            return [bool(b) for b in r.bits[:count]]
        return list(r.registers)

    def read_values(self, address, types, table="holding", word_order="high_first"):
        return decode(types, self.read(table, address, sum(WIDTH[t] for t in types)), word_order)

    def expect(self, code, name, *args, what="", **kw):
        """A request that must get exception `code`."""
        r = self._call(name, *args, **kw)
        expect_exception(r, code, what or "%s%r" % (name, args))
        self.tally.exception(code)

    def write_coil(self, address, value):
        expect_ok(self._call("write_coil", address, value), "write coil %d" % address)
        self.tally.ok(written=1)

    def write_coils(self, address, values):
        expect_ok(self._call("write_coils", address, values), "write coils %d.." % address)
        self.tally.ok(written=len(values))

    def write_register(self, address, value):
        expect_ok(self._call("write_register", address, value & 0xFFFF), "write register %d" % address)
        self.tally.ok(written=1)

    def write_registers(self, address, regs, values):
        """FC 16 of `regs`; `values` is how many tag values they hold (what the server counts)."""
        expect_ok(self._call("write_registers", address, list(regs)), "write registers %d.." % address)
        self.tally.ok(written=values)

    def write_values(self, address, typed, word_order="high_first"):
        self.write_registers(address, encode(typed, word_order), len(typed))

    def readwrite(self, read_address, read_count, write_address, regs, values):
        r = self._call("readwrite_registers", read_address=read_address, read_count=read_count,
                       write_address=write_address, write_registers=list(regs))
        expect_ok(r, "FC 23 write %d.. read %d.." % (write_address, read_address))
        self.tally.ok(written=values)
        return list(r.registers)

    def wait_read(self, table, address, count, want, what, timeout=ECHO_TIMEOUT):
        """Reads until the values are `want` (a list, or a predicate); every poll is tallied."""
        pred = want if callable(want) else (lambda v: v == want)

        def poll():
            v = self.read(table, address, count)
            return pred(v), v
        return wait_until(poll, what, timeout)[0]

    def wait_values(self, address, types, want, what, table="holding", word_order="high_first"):
        def poll():
            v = self.read_values(address, types, table, word_order)
            return all(same_value(t, a, b) for t, a, b in zip(types, v, want)), v
        return wait_until(poll, what)[0]


# --- checks shared by the test scripts ---------------------------------------

# (first register, first register of the read-only copies, types) of the
# writable %MD and %ML blocks of peers_common.yaml.
MD, MD_R, MD_T = 2108, 2128, ["DINT", "UDINT", "DWORD", "REAL"]
ML, ML_R, ML_T = 4216, 4256, ["LINT", "ULINT", "LWORD", "LREAL", "TIME"]


def check_equal(got, want, what):
    if got != want:
        raise AssertionError("%s: got %r, expected %r" % (what, got, want))


def check_true(cond, message):
    if not cond:
        raise AssertionError(message)


def check_values(types, got, want, what):
    if len(got) != len(want) or not all(same_value(t, a, b) for t, a, b in zip(types, got, want)):
        raise AssertionError("%s: got %r, expected %r" % (what, got, want))


def pymodbus_unanswered(port):
    """A pymodbus read from a client the server refuses: an error without an exception code, or an exception."""
    c = pymodbus_client(port, timeout=2)
    try:
        r = c.read_holding_registers(1024, 1, slave=1)
    except Exception as e:  # noqa: BLE001
        r = e
    c.close()
    return isinstance(r, Exception) or (r.isError() and not hasattr(r, "exception_code")), r


class OneConnectionDevice:
    """A Modbus TCP device that takes one connection at a time, as many
    drives do: a second connection is accepted and closed at once (counted
    as refused). FC 6 only: echoes the request and keeps the register's
    value (16 registers); other codes get exception 01. For the tests of
    modbus_client drivers replaced by an online change."""

    def __init__(self):
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port = self.sock.getsockname()[1]
        self.registers = [0] * 16
        self.accepted = 0
        self.refused = 0
        self.closed = 0  # the active connection ended (closed by the client)
        self.active = None
        self.lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            with self.lock:
                if self.active is not None:
                    self.refused += 1
                    c.close()
                    continue
                self.accepted += 1
                self.active = c
            threading.Thread(target=self._serve, args=(c,), daemon=True).start()

    def _serve(self, c):
        try:
            while True:
                head = self._exact(c, 7)
                if head is None:
                    break
                tid, proto, length, unit = struct.unpack(">HHHB", head)
                pdu = self._exact(c, length - 1)
                if pdu is None:
                    break
                if pdu[0] == 6:
                    address, value = struct.unpack(">HH", pdu[1:5])
                    self.registers[address % 16] = value
                    c.sendall(head + pdu)
                else:
                    c.sendall(struct.pack(">HHHBBB", tid, 0, 3, unit, pdu[0] | 0x80, 1))
        except OSError:
            pass
        with self.lock:
            self.closed += 1
            self.active = None
        c.close()

    @staticmethod
    def _exact(c, n):
        b = b""
        while len(b) < n:
            k = c.recv(n - len(b))
            if not k:
                return None
            b += k
        return b

    def wait_register(self, address, value, timeout=20):
        deadline = time.monotonic() + timeout
        while self.registers[address] != value:
            if time.monotonic() > deadline:
                raise AssertionError("register %d is %d, not %d, after %d s" % (address, self.registers[address], value, timeout))
            time.sleep(0.01)
