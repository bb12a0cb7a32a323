"""The event log as an audit trail: `syncplc run tests/peers/peers.yaml --db
FILE` while `syncplc events --db FILE --follow` runs beside it. A pymodbus
client writes a register and a coil: each write appears in the follower's
output while the PLC runs, with the tag, the value and the client's
address (the pymodbus socket's own ip:port). After the stop the sqlite3 shell
(not our code) finds the writes, the start and the stop in the `events`
table and `PRAGMA integrity_check` is ok; `syncplc events --kind hmi-write`
lists exactly the writes. Then a project whose allowed_clients leaves out
127.0.0.1 refuses a connection, and the log says so with the client's address.

    /usr/bin/python3 tests/peers/test_audit_trail.py build/syncplc
"""

import os
import socket
import subprocess
import sys
import threading

import peerlib as P

QW_INT, Q_CMD = 4, 0


def sqlite(db, sql):
    r = subprocess.run(["sqlite3", "-readonly", db, sql], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, timeout=30)
    P.check_true(r.returncode == 0, "sqlite3 %r failed: %s" % (sql, r.stdout))
    return r.stdout.strip()


class Follower:
    """`syncplc events --follow`, its lines collected by a thread."""

    def __init__(self, binary, db):
        self.lines = []
        self.proc = subprocess.Popen([binary, "events", "--db", db, "--follow"], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        P._running.append(self.proc)
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def wait_for(self, *parts):
        def seen():
            hits = [l for l in self.lines if all(p in l for p in parts)]
            return (bool(hits), self.lines[-20:])
        return P.wait_until(seen, "syncplc events --follow printing %r" % (parts,), timeout=30)

    def stop(self):
        self.proc.terminate()
        self.proc.wait(timeout=30)


def main():
    binary = P.syncplc_binary()
    db = os.path.join(P.STATE_DIR, "audit", "plc.db")
    tally = P.Tally()
    server = P.Server(binary, P.project("peers.yaml"), extra=["--db", db])
    follower = None
    try:
        # run creates the log before its server listens: follow it from now on.
        follower = Follower(binary, db)
        follower.wait_for("start", "peers.yaml")
        peer = P.Peer(server.port, tally)
        ip, port = peer.c.socket.getsockname()
        client = "%s:%d" % (ip, port)
        peer.write_register(QW_INT, 1234)
        peer.write_coil(Q_CMD, True)
        # Seen while the PLC runs, with the client's address.
        follower.wait_for("hmi-write", "qw_int := 1234", "client " + client)
        follower.wait_for("hmi-write", "q_cmd := TRUE", "client " + client)
        # The store status block (docs/modbus.md, "Store status"): ok, a commit
        # made (seconds since it, not 65535), nothing dropped, no failed run.
        st = peer.wait_read("input", 8990, 8, lambda v: v[0] == 0 and v[1] < 65535, "store status ok, committed")
        P.check_equal(st[4:], [0, 0, 0, 0], "store status: no record dropped, no failed run")
        peer.close()
    finally:
        if follower:
            follower.stop()
        server.stop()

    rows = sqlite(db, "SELECT message || ' from ' || client FROM events WHERE kind = 'hmi-write' ORDER BY id")
    P.check_equal(rows.splitlines(), ["qw_int := 1234 from " + client, "q_cmd := TRUE from " + client],
                  "the audit trail in the events table")
    kinds = sqlite(db, "SELECT group_concat(kind, ' ') FROM (SELECT kind FROM events ORDER BY id)").split()
    P.check_equal((kinds[0], kinds[-1]), ("start", "stop"), "the log begins with start and ends with stop")
    stop = sqlite(db, "SELECT message FROM events WHERE kind = 'stop'")
    P.check_true("SIGTERM" in stop, "the stop event says why: " + stop)
    P.check_equal(sqlite(db, "PRAGMA integrity_check"), "ok", "integrity_check")
    listed = P.run([binary, "events", "--db", db, "--kind", "hmi-write"])
    P.check_equal(listed.returncode, 0, "syncplc events --kind exit status:\n" + listed.stdout)
    lines = listed.stdout.splitlines()
    P.check_equal(len(lines), 2, "syncplc events --kind hmi-write lines:\n" + listed.stdout)
    P.check_true("qw_int := 1234" in lines[0] and lines[0].endswith("client " + client), lines[0])

    # A refused connection is in the log with the address it came from.
    denied_db = os.path.join(P.STATE_DIR, "denied", "plc.db")
    server = P.Server(binary, P.project("peers_denied.yaml"), extra=["--db", denied_db])
    try:
        s = socket.create_connection(("127.0.0.1", server.port), timeout=5)
        refused_from = "%s:%d" % s.getsockname()
        P.check_true(P.closed_by_server(s), "the server closes a connection from outside allowed_clients")
        s.close()
    finally:
        server.stop()
    rows = sqlite(denied_db, "SELECT message || ' from ' || client FROM events WHERE kind = 'modbus-refused'")
    P.check_equal(rows, "connection refused: not in allowed_clients from " + refused_from, "the refusal's event")
    print("test_audit_trail: OK")


if __name__ == "__main__":
    sys.exit(main())
