"""PLC to PLC: one `syncplc run` (A) reads and writes another's (B,
plc_b.yaml) tags through B's Modbus server with the modbus_client driver;
then the reaction stop against a dead third device (mb_device.py): A's task
stops with its safe outputs, which still reach B.

  /usr/bin/python3 tests/peers/test_plc_to_plc.py build/syncplc
"""
import atexit
import os
import shutil
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402
from test_modbus_client import Device  # noqa: E402

PROJECT_A = """
project: {{name: plc_a, version: 1.0.0}}
tasks: [{{name: main, period: 10ms}}]
tags:
  - {{name: a_cmd, type: INT, hmi: readwrite, safe: 99, modbus: {{table: holding_register, address: 0}}}}
  - {{name: a_level, type: REAL, hmi: readwrite, modbus: {{table: holding_register, address: 2}}}}
  - {{name: a_echo, type: INT, hmi: read, modbus: {{table: input_register, address: 0}}}}
  - {{name: a_flag, type: BOOL, hmi: read, modbus: {{table: discrete_input, address: 0}}}}
  - {{name: a_ok, type: BOOL, hmi: read, modbus: {{table: discrete_input, address: 1}}}}
  - {{name: x_v, type: "ARRAY[1..2] OF DINT", hmi: read, modbus: {{table: input_register, address: 10}}}}
drivers:
  - name: net
    type: modbus_client
    devices:
      - {{name: plc_b, port: {b_port}, response_timeout: 500ms}}
      - {{name: x, port: {x_port}, response_timeout: 200ms, reconnect_min: 50ms, reaction: stop, stale_after: 300ms}}
    groups:
      - {{name: cmd, device: plc_b, function: write_single_register, address: 0, type: INT}}
      - {{name: level, device: plc_b, function: 16, address: 2, type: REAL, on_change: true}}
      - {{name: echo, device: plc_b, function: read_input_registers, address: 0, type: INT}}
      - {{name: flag, device: plc_b, function: read_discrete_inputs, address: 0}}
      - {{name: xr, device: x, function: 3, address: 0, count: 2, type: DINT}}
    bind: {{cmd: a_cmd, level: a_level, echo: a_echo, flag: a_flag, echo_ok: a_ok, xr: x_v}}
modbus: {{}}
"""


def main():
    binary = peerlib.syncplc_binary()
    b = peerlib.Server(binary, peerlib.project("plc_b.yaml"))
    x = Device(peerlib.free_port())
    tmp = tempfile.mkdtemp(prefix="plc2plc-")
    atexit.register(shutil.rmtree, tmp, True)
    path = os.path.join(tmp, "plc_a.yaml")
    with open(path, "w") as f:
        f.write(PROJECT_A.format(b_port=b.port, x_port=x.port))
    a = peerlib.Server(binary, path, extra=("--db", os.path.join(tmp, "plc_a.db")))  # one database per instance
    ta, tb = peerlib.Tally(), peerlib.Tally()
    hmi_a, hmi_b = peerlib.Peer(a.port, ta), peerlib.Peer(b.port, tb)

    # A reads B: the flag B's program sets, the echo of B's setpoint.
    peerlib.wait_until(lambda: (hmi_a.read("discrete", 0, 2) == [True, True], hmi_a.read("discrete", 0, 2)), "A reads B")
    # A writes B: a setpoint written to A goes to B's tag, B's program echoes it, A reads the echo back.
    hmi_a.write_register(0, 321)
    hmi_a.write_values(2, [("REAL", 2.5)])
    peerlib.wait_until(lambda: (hmi_b.read_values(0, ["INT"])[0] == 321, hmi_b.read_values(0, ["INT"])), "B's b_set")
    peerlib.wait_until(lambda: (hmi_b.read_values(2, ["REAL"])[0] == 2.5, hmi_b.read_values(2, ["REAL"])), "B's b_level")
    peerlib.wait_until(lambda: (hmi_a.read_values(0, ["INT"], table="input")[0] == 321,
                                hmi_a.read_values(0, ["INT"], table="input")), "A's echo of B")
    # Device x may have refused A's first connection (it prints "ready" before it listens): A reconnects after its back-off.
    peerlib.wait_until(lambda: (hmi_a.read_values(10, ["DINT", "DINT"], table="input") == [0x12345, 0],
                                hmi_a.read_values(10, ["DINT", "DINT"], table="input")), "A reads device x")
    print("PLC A reads and writes PLC B's tags: ok")

    # Reaction stop: the third device dies; A's task stops with its safe outputs (a_cmd 99), which reach B.
    x.kill()
    t0 = time.monotonic()
    peerlib.wait_until(lambda: (hmi_b.read_values(0, ["INT"])[0] == 99, hmi_b.read_values(0, ["INT"])),
                       "A's safe output at B")
    print("device x killed: A's task stopped, its safe output reached B after %.0f ms" % ((time.monotonic() - t0) * 1000))
    hmi_a.close()
    hmi_b.close()
    # A ends by itself (every task stopped, status 3); the minute only ends a hang.
    try:
        rc = a.proc.wait(timeout=60)
    except Exception:
        a.proc.send_signal(signal.SIGTERM)
        a.proc.wait(timeout=30)
        raise AssertionError("A did not end by itself with its only task stopped")
    assert rc == 3, "A's exit status %d, expected 3 (every task stopped)" % rc
    a._drain.join(timeout=10)
    err = "".join(a.stderr_lines)
    for text in ("modbus_client net.xr: stale past stale_after, stopping the task", "outputs driven to their safe values"):
        assert text in err, "no '%s' in A's stderr:\n%s" % (text, err)
    for bad in ("ERROR: AddressSanitizer", "runtime error:", "WARNING: ThreadSanitizer"):
        assert bad not in err, "sanitizer report on A's stderr:\n" + err
    b.stop()
    print("PASS")


if __name__ == "__main__":
    main()
