"""Writes that cannot take effect are not acknowledged: `syncplc run
tests/peers/peers_stopped.yaml`, whose task `bad` is stopped by its watchdog on
its first scan while `fast` runs on. Every write to a tag of `bad` (FC 5, 6,
15, 16, 23) is exception 04 (server device failure), and so is a write that
spans a tag of `fast` and one of `bad`: nothing of it is queued, for either
task. Writes to `fast` alone and every read are served as before. The
counters must match at the end, and SIGTERM still ends the run with status 0.

    /usr/bin/python3 tests/peers/test_stopped_task.py build/syncplc
"""

import sys
import time

import peerlib as P

DEVICE_FAILURE = 0x04
FAST_W, BAD_W, FAST_C, BAD_C = 1024, 1025, 0, 1


def main():
    binary = P.syncplc_binary()
    tally = P.Tally()
    server = P.Server(binary, P.project("peers_stopped.yaml"))
    try:
        P.wait_until(lambda: (any("bad: task stopped by its watchdog" in l for l in server.stderr_lines), None),
                     "the watchdog stopping task bad")
        peer = P.Peer(server.port, tally)
        peer.expect(DEVICE_FAILURE, "write_register", BAD_W, 7, what="FC 6 to a stopped task")
        peer.expect(DEVICE_FAILURE, "write_coil", BAD_C, True, what="FC 5 to a stopped task")
        peer.expect(DEVICE_FAILURE, "write_registers", BAD_W, [7], what="FC 16 to a stopped task")
        peer.expect(DEVICE_FAILURE, "write_coils", BAD_C, [True], what="FC 15 to a stopped task")
        peer.expect(DEVICE_FAILURE, "readwrite_registers", what="FC 23 to a stopped task", read_address=FAST_W,
                    read_count=2, write_address=BAD_W, write_registers=[7])
        # All or none across tasks: fast's half of these is not queued either.
        peer.expect(DEVICE_FAILURE, "write_registers", FAST_W, [8, 9], what="FC 16 spanning fast and bad")
        peer.expect(DEVICE_FAILURE, "write_coils", FAST_C, [True, True], what="FC 15 spanning fast and bad")
        time.sleep(0.2)  # a hundred scans of fast: a queued value would show
        P.check_equal(peer.read("holding", FAST_W, 2), [1, 2], "nothing of the refused writes")
        P.check_equal(peer.read("coil", FAST_C, 2), [False, False], "nothing of the refused coil writes")
        # fast alone is written as before.
        peer.write_register(FAST_W, 9)
        peer.wait_read("holding", FAST_W, 1, [9], "the write to the running task")
        peer.write_coil(FAST_C, True)
        peer.wait_read("coil", FAST_C, 1, [True], "the coil of the running task")
        peer.close()
    finally:
        counters = server.stop()
    P.check_counters(counters, tally, requests_at_least=False)
    P.check_true("STOPPED" in counters.text, "the statistics show bad STOPPED:\n" + counters.text)
    print("test_stopped_task: OK")


if __name__ == "__main__":
    sys.exit(main())
