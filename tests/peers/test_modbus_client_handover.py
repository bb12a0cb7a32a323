"""Online change of a changed modbus_client driver against a device that
takes one connection at a time (as many drives do): a second connection is
accepted and closed at once ("refused" below). `syncplc run` starts with a
driver writing register 0; the project file then gains a second write group
(the driver's settings change, so the change replaces it) and SIGHUP
reloads it. The new driver must take over the old one's connection at the
switch: the device sees one connection for the whole run, none refused and
none closed, and the new group's value arrives through it.

  /usr/bin/python3 tests/peers/test_modbus_client_handover.py build/syncplc
"""
import os
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib as P  # noqa: E402

PROJECT = """
project: {{name: handover, version: "{version}"}}
tasks: [{{name: main, period: 10ms}}]
tags:
  - {{name: cmd, type: INT, init: 5}}
  - {{name: cmd2, type: INT, init: 9}}
  - {{name: w_ok, type: BOOL}}
drivers:
  - name: io
    type: modbus_client
    devices: [{{name: dev, port: {port}, response_timeout: 200ms, connect_timeout: 200ms, reconnect_min: 20ms}}]
    groups:
      - {{name: w, function: write_single_register, address: 0, every: 20ms}}
{extra}    bind: {{w: cmd, w_ok: w_ok{extra_bind}}}
"""


PROJECT_TWO = """
project: {{name: handover2, version: "{version}"}}
tasks: [{{name: main, period: 10ms}}]
tags:
  - {{name: cmd, type: INT, init: {value}}}
drivers:
  - name: io_a
    type: modbus_client
    devices: [{{name: dev, port: {port_a}, response_timeout: 200ms, connect_timeout: 200ms, reconnect_min: 20ms}}]
    groups:
      - {{name: w, function: write_single_register, address: {address}, every: 20ms}}
    bind: {{w: cmd}}
  - name: io_b
    type: modbus_client
    devices: [{{name: dev, port: {port_b}, response_timeout: 200ms, connect_timeout: 200ms, reconnect_min: 20ms}}]
    groups:
      - {{name: w, function: write_single_register, address: {address}, every: 20ms}}
    bind: {{w: cmd}}
"""


def two_drivers_of_one_type(binary):
    """Issue 21: two modbus_client drivers replaced in one change, six times.
    Each new driver takes over its own predecessor's one connection, never
    another's: each device sees one connection for the whole run."""
    dev_a, dev_b = P.OneConnectionDevice(), P.OneConnectionDevice()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "handover2.yaml")

        def write(version):
            with open(path, "w") as f:
                f.write(PROJECT_TWO.format(version=version, port_a=dev_a.port, port_b=dev_b.port,
                                           address=version % 8, value=100))

        write(0)
        server = P.Server(binary, path)
        try:
            dev_a.wait_register(0, 100)
            dev_b.wait_register(0, 100)
            for v in range(1, 7):
                write(v)
                server.proc.send_signal(signal.SIGHUP)
                P.wait_until(lambda: (sum("reloaded" in l for l in server.stderr_lines) >= v, None),
                             "reload %d" % v, timeout=20)
                # The new group's address, written by the new driver (cmd keeps its value across a change).
                dev_a.wait_register(v % 8, 100)
                dev_b.wait_register(v % 8, 100)
            time.sleep(0.3)
            stderr = "".join(server.stderr_lines)
            for name, dev in (("a", dev_a), ("b", dev_b)):
                P.check_true(dev.accepted == 1 and dev.refused == 0 and dev.closed == 0,
                             "device %s saw %d connections, refused %d, %d closed over six changes\n%s"
                             % (name, dev.accepted, dev.refused, dev.closed, stderr))
        finally:
            server.stop()
    print("two drivers of one type replaced six times: one connection each, none leaked")


def main():
    binary = P.syncplc_binary()
    two_drivers_of_one_type(binary)
    dev = P.OneConnectionDevice()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "handover.yaml")

        def write(version, extra="", extra_bind=""):
            with open(path, "w") as f:
                f.write(PROJECT.format(version=version, port=dev.port, extra=extra, extra_bind=extra_bind))

        write("1")
        server = P.Server(binary, path)
        try:
            dev.wait_register(0, 5)
            write("2", extra="      - {name: w2, function: 6, address: 1, every: 20ms}\n", extra_bind=", w2: cmd2")
            server.proc.send_signal(signal.SIGHUP)
            P.wait_until(lambda: (any("reloaded" in l for l in server.stderr_lines), None), "the reload message",
                         timeout=20)
            dev.wait_register(1, 9)  # the new driver's new group, through the connection it took over
            time.sleep(0.3)
            stderr = "".join(server.stderr_lines)
            P.check_true("restarted" in stderr, "the change did not replace the driver:\n" + stderr)
            P.check_true(dev.accepted == 1 and dev.refused == 0 and dev.closed == 0,
                         "the device saw %d connections, refused %d, %d closed: the connection was not handed over\n%s"
                         % (dev.accepted, dev.refused, dev.closed, stderr))
            P.check_true("connect failed" not in stderr and "connection lost" not in stderr,
                         "a fault event across the change:\n" + stderr)
        finally:
            server.stop()
    print("one connection across the online change; the new group written through it")
    print("test_modbus_client_handover: OK")


if __name__ == "__main__":
    sys.exit(main())
