"""The kill test (issue 12): a retained counter incremented every scan by a
1 ms task; `syncplc run` killed with SIGKILL at random moments, N times in a
row. Every check is counted in values and commits, none in seconds, so a
loaded machine makes the test slower, never wrong. In every round:

  - the store commits while the PLC runs: before the kill, the sqlite3 shell
    (read-only) must read a stored value at least as new as a count a Modbus
    client (pymodbus) read in this round, after the round's random run (a
    store that stopped writing, or wrote only once after the start, never
    does: the wait for it ends at a generous guard against a hang, and the
    test fails);
  - after the kill, `PRAGMA integrity_check` is ok and the stored value is
    at least that committed value: nothing acknowledged as stored is lost,
    and the restored value advances from kill to kill;
  - the restarted PLC goes on from the stored value: its first Modbus read
    is at least the stored value and at most the stored value plus the ms
    it ran (one count per scan).

How much counting a kill loses (the last Modbus read minus the stored
value, in ms of counting) is printed per kill, with the worst and the
median: a measurement of the store's interval and commit time, reported in
docs/benchmarks.md (scripts/retain_soak.sh), not a bound a loaded machine
could break.

Usage: /usr/bin/python3 tests/store/test_retain_kill.py build/syncplc [KILLS] [--seed N]
"""

import os
import random
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "peers"))
import peerlib as P  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
# RETAIN_KILL_PROJECT: another project with the same counter (bench/retain_kill_10k.sh adds 10,000 more).
PROJECT = os.environ.get("RETAIN_KILL_PROJECT", os.path.join(HERE, "retain_kill.yaml"))
INTERVAL_MS = 100       # store: retain_interval in retain_kill.yaml
# Only against a hang: a store that commits at all commits within a few
# intervals, whatever the load.
COMMIT_GUARD_S = 120


def sql(db, query):
    r = subprocess.run(["sqlite3", "-readonly", db, query], capture_output=True, text=True, timeout=30)
    if r.returncode != 0:
        raise AssertionError("sqlite3 %r: %s" % (query, r.stderr))
    return r.stdout.strip()


def stored(db):
    """The counter's stored value (the UNIT_DELAY's state: DINT in the low bytes), or None."""
    h = sql(db, "SELECT hex(value) FROM retain_value WHERE name = 'last'")
    if not h:
        return None
    return int.from_bytes(bytes.fromhex(h)[:4], "little", signed=True)


def read_count(c):
    r = c.read_holding_registers(0, 2, slave=1)
    if r.isError():
        return None
    return P.decode(["DINT"], r.registers)[0]


def main():
    binary = P.syncplc_binary()
    kills = int(sys.argv[2]) if len(sys.argv) > 2 and not sys.argv[2].startswith("-") else 10
    seed = int(sys.argv[sys.argv.index("--seed") + 1]) if "--seed" in sys.argv else int(time.time())
    rng = random.Random(seed)
    db = os.path.join(P.STATE_DIR, "kill.db")
    print("kill test: %d kills, seed %d, database %s" % (kills, seed, db))
    losses = []
    expect_restored = None
    for k in range(kills):
        started = time.monotonic()
        server = P.Server(binary, PROJECT, extra=("--db", db))
        head = "".join(server.stderr_lines)
        if expect_restored is not None and ("retain: warm start: " not in head or " not restored" in head):
            raise AssertionError("restart %d: no restore reported:\n%s" % (k, head))
        c = P.pymodbus_client(server.port)
        first = None
        while first is None and time.monotonic() - started < 30:
            v = read_count(c)
            if v is not None and v > 0:
                first = v
        ran_ms = (time.monotonic() - started) * 1000
        if first is None:
            raise AssertionError("restart %d: no Modbus read of count" % k)
        if expect_restored is not None and not (expect_restored <= first <= expect_restored + ran_ms + 50):
            raise AssertionError("restart %d: first read %d, stored %d, ran %.0f ms: not going on from the stored value"
                                 % (k, first, expect_restored, ran_ms))
        # Run a random while, reading over Modbus and from the database.
        until = time.monotonic() + rng.uniform(0.15, 1.2)
        last_read = first
        while time.monotonic() < until:
            v = read_count(c)
            if v is not None:
                last_read = v
            time.sleep(rng.uniform(0, 0.02))
        # The store must commit a value at least as new as the last count read
        # (counted: commits seen by the sqlite3 shell; the guard only ends a hang).
        mark = last_read
        committed = None
        guard = time.monotonic() + COMMIT_GUARD_S
        while committed is None:
            s = stored(db)
            if s is not None and s >= mark:
                committed = s
            elif time.monotonic() > guard:
                raise AssertionError("round %d: the store never committed a count >= %d (read over Modbus before): "
                                     "last stored %r; it stopped writing. Its stderr:\n%s"
                                     % (k, mark, s, "".join(server.stderr_lines)))
            else:
                v = read_count(c)
                if v is not None:
                    last_read = v
                time.sleep(0.01)
        # Then the kill at a random phase of the store's cycle (so that the
        # loss window printed below is what a kill at any moment loses), right
        # after a read: the read is the last value the client saw.
        until = time.monotonic() + rng.uniform(0, 2.5 * INTERVAL_MS / 1000)
        while time.monotonic() < until:
            v = read_count(c)
            if v is not None:
                last_read = v
        v = read_count(c)
        if v is not None:
            last_read = v
        server.proc.send_signal(signal.SIGKILL)
        server.proc.wait(timeout=30)
        c.close()
        check = sql(db, "PRAGMA integrity_check")
        if check != "ok":
            raise AssertionError("kill %d: integrity_check: %s" % (k, check))
        after = stored(db)
        if after is None or after < committed:
            raise AssertionError("kill %d: stored %r, lower than %d committed before the kill" % (k, after, committed))
        if expect_restored is not None and after <= expect_restored:
            raise AssertionError("kill %d: stored %d, not past %d stored at the kill before" % (k, after, expect_restored))
        loss = last_read - after
        losses.append(loss)
        print("kill %d: last read %d, stored %d, committed before the kill %d: lost %d ms of counting"
              % (k, last_read, after, committed, loss))
        expect_restored = after
    median = sorted(losses)[len(losses) // 2]
    print("kill test ok: %d kills; loss window (ms of counting lost) max %d, median %d, mean %.1f, over one interval %d; interval %d ms"
          % (kills, max(losses), median, sum(losses) / len(losses), sum(1 for x in losses if x > INTERVAL_MS), INTERVAL_MS))

if __name__ == "__main__":
    main()
