"""The Modbus TCP client driver's `at_stop` at a clean stop of `syncplc run`,
against Debian's pymodbus server (mb_device.py, not ours):

  1. at_stop: safe, --duration's end: the write group's register holds the
     tag's safe value when run has exited, and run's counters say the
     device acknowledged it (w.safe_at_stop=1);
  2. at_stop: safe, SIGTERM: the same;
  3. at_stop: keep (the default): the register keeps the last value written.

The group writes the tag's value 5 every 50 ms: the safe value -1 found
after the stop can only have been written by at_stop.

  /usr/bin/python3 tests/peers/test_modbus_client_at_stop.py build/syncplc
"""
import logging
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peerlib  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
logging.disable(logging.CRITICAL)  # pymodbus logs a refused connection while the device starts
REGISTER = 60

PROJECT = """
tasks: [{{name: main, period: 10ms}}]
tags:
  - {{name: cmd, type: INT, init: 5, safe: -1}}
drivers:
  - name: io
    type: modbus_client
    at_stop: {at_stop}
    devices: [{{name: dev, port: {port}, response_timeout: 200ms, connect_timeout: 200ms}}]
    groups: [{{name: w, function: write_single_register, address: {register}, every: 50ms}}]
    bind: {{w: cmd}}
"""



def start_device(port):
    proc = subprocess.Popen(["/usr/bin/python3", os.path.join(HERE, "mb_device.py"), str(port)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    peerlib._running.append(proc)
    if proc.stdout.readline().strip() != "ready":
        raise AssertionError("mb_device.py did not start")
    return proc


def register(port, timeout=20):
    """The device's holding register REGISTER (INT), read with pymodbus."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            c = peerlib.pymodbus_client(port, timeout=1)
            try:
                r = c.read_holding_registers(REGISTER, 1, slave=1)
                if r is not None and not r.isError():
                    v = r.registers[0]
                    return v - 0x10000 if v >= 0x8000 else v
            finally:
                c.close()
        except AssertionError:
            pass
        if time.monotonic() > deadline:
            raise AssertionError("the device on port %d does not answer" % port)
        time.sleep(0.05)


def wait_for(port, value, timeout=20):
    deadline = time.monotonic() + timeout
    while register(port) != value:
        if time.monotonic() > deadline:
            raise AssertionError("the device's register is %d, not %d, after %d s" % (register(port), value, timeout))
        time.sleep(0.02)


def run(binary, tmp, at_stop, how):
    port = peerlib.free_port()
    dev = start_device(port)
    try:
        path = os.path.join(tmp, "at_stop_%s_%s.yaml" % (at_stop, how))
        with open(path, "w") as f:
            f.write(PROJECT.format(at_stop=at_stop, port=port, register=REGISTER))
        args = [binary, "run", path, "--no-status", "-d", "3s" if how == "duration" else peerlib.RUN_LIMIT]
        proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        peerlib._running.append(proc)
        # The first scan's value reaches the device.
        wait_for(port, 5)
        if how == "sigterm":
            proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=60)
        if proc.returncode != 0:
            raise AssertionError("syncplc run exited with %d:\n%s" % (proc.returncode, out))
        value = register(port)
        return value, out
    finally:
        dev.kill()
        dev.wait()


def main():
    binary = peerlib.syncplc_binary()
    with tempfile.TemporaryDirectory() as tmp:
        for how in ("duration", "sigterm"):
            value, out = run(binary, tmp, "safe", how)
            peerlib.check_true(value == -1, "at_stop safe (%s): the register holds %d, not the safe value -1\n%s"
                               % (how, value, out))
            peerlib.check_true(re.search(r"\bw: .*safe_at_stop=1\b", out) is not None,
                               "at_stop safe (%s): run does not report the safe values acknowledged\n%s" % (how, out))
            print("at_stop safe (%s): the device holds the safe value -1 after the stop" % how)
        value, out = run(binary, tmp, "keep", "sigterm")
        peerlib.check_true(value == 5, "at_stop keep: the register holds %d, not the last value 5\n%s" % (value, out))
        peerlib.check_true("safe_at_stop" not in out, "at_stop keep: run reports safe_at_stop\n%s" % out)
        print("at_stop keep: the device keeps the last value 5 after the stop")
    print("OK")


if __name__ == "__main__":
    main()
