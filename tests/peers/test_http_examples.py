"""Every shell block of docs/http-api.md's "Examples", run in order by bash
against a real `syncplc run` (the address put in for 127.0.0.1:8080), each
answer checked: the documentation's examples work as written.

    /usr/bin/python3 tests/peers/test_http_examples.py build/syncplc
"""

import json
import os
import re
import subprocess
import time

import peerlib

BINARY = peerlib.syncplc_binary()
DOC = os.path.join(peerlib.HERE, "..", "..", "docs", "http-api.md")
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
PASSWORD = "alice-secret-9"


def blocks():
    text = open(DOC).read()
    examples = text[text.index("## Examples"):]
    return re.findall(r"```sh\n(.*?)```", examples, re.S)


def main():
    p = subprocess.run([BINARY, "user", "add", "alice", "--role", "engineer", "--password-stdin", "--db", DB],
                       input=PASSWORD + "\n", text=True, capture_output=True, timeout=60)
    assert p.returncode == 0, p.stderr
    srv = peerlib.Server(BINARY, peerlib.project("http_api.yaml"), extra=["--http", "127.0.0.1:0", "--db", DB])
    port, deadline = None, time.monotonic() + 30
    while port is None and time.monotonic() < deadline:
        for line in list(srv.stderr_lines):
            m = re.search(r"HTTP API on http://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
        time.sleep(0.05)
    assert port, "".join(srv.stderr_lines)
    found = blocks()
    assert len(found) == 4, "expected the four example blocks, found %d" % len(found)
    env = dict(os.environ, PASSWORD=PASSWORD)
    outputs = []
    for b in found:
        script = "set -eu\n" + b.replace("127.0.0.1:8080", "127.0.0.1:%d" % port)
        r = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, "example failed (%d):\n%s\n%s" % (r.returncode, b, r.stderr)
        outputs.append(r.stdout)
    # Each answer is the documented one.
    status = outputs[0].splitlines()
    assert json.loads(status[0])["runtime"]["program"] == "http_api", status[0]
    assert json.loads(status[1])["values"] == {"speed": 1.5, "pos[1]": 0.1}, status[1]
    answers = [json.loads(l) for l in outputs[1].splitlines() if l.strip()]
    assert answers[0]["ok"] and answers[0]["tag"] == "speed", answers
    assert answers[1]["ok"] and answers[1]["ref"] == "pos[2]", answers
    assert answers[2]["ok"] and answers[2]["ref"] == "pos[2]", answers
    assert answers[3] == {}, answers
    assert "event: values" in outputs[2] and '"speed":2.5' in outputs[2], outputs[2]
    events = json.loads(outputs[3])["events"]
    assert len(events) == 5 and any("speed := 2.5" in e["message"] for e in events), events
    srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
