"""Every shell block of docs/http-api.md's "Examples", run in order by bash
against a real `syncplc run` (the address put in for 127.0.0.1:8080), each
answer checked: the documentation's examples work as written.

    /usr/bin/python3 tests/peers/test_http_examples.py build/syncplc
"""

import json
import os
import re
import subprocess

import peerlib

BINARY = peerlib.syncplc_binary()
DOC = os.path.join(peerlib.HERE, "..", "..", "docs", "http-api.md")
DB = os.path.join(peerlib.STATE_DIR, "plc.db")
PASSWORD = "alice-secret-9"


def blocks():
    text = open(DOC).read()
    examples = text[text.index("## Examples"):]
    return re.findall(r"```sh\n(.*?)```", examples, re.S)


def answers(text):
    """The JSON documents curl printed one after the other (no newline between)."""
    out, at, dec = [], 0, json.JSONDecoder()
    while at < len(text):
        if text[at].isspace():
            at += 1
            continue
        doc, at = dec.raw_decode(text, at)
        out.append(doc)
    return out


def main():
    p = subprocess.run([BINARY, "user", "add", "alice", "--role", "engineer", "--password-stdin", "--db", DB],
                       input=PASSWORD + "\n", text=True, capture_output=True, timeout=60)
    assert p.returncode == 0, p.stderr
    srv = peerlib.Server(BINARY, peerlib.project("http_api.yaml"), extra=["--http", "127.0.0.1:0", "--db", DB])
    port = srv.http_port()
    found = blocks()
    assert len(found) == 4, "expected the four example blocks, found %d" % len(found)
    env = dict(os.environ, PASSWORD=PASSWORD)
    outputs = []
    for i, b in enumerate(found):
        if i == 3:
            # The store thread writes events shortly after they happen.
            import http.client

            def written():
                c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
                c.request("GET", "/api/v1/events?kind=hmi-write")
                return "speed := 2.5" in c.getresponse().read().decode(), None
            peerlib.wait_until(written, "the write in the event log", timeout=30)
        script = "set -eu\n" + b.replace("127.0.0.1:8080", "127.0.0.1:%d" % port)
        r = subprocess.run(["bash", "-c", script], env=env, capture_output=True, text=True, timeout=60)
        assert r.returncode == 0, "example failed (%d):\n%s\n%s" % (r.returncode, b, r.stderr)
        outputs.append(r.stdout)
    # Each answer is the documented one.
    status = answers(outputs[0])
    assert status[0]["runtime"]["program"] == "http_api", status[0]
    assert status[1]["values"] == {"speed": 1.5, "pos[1]": 0.1}, status[1]
    changes = answers(outputs[1])
    assert changes[0]["ok"] and changes[0]["tag"] == "speed", changes
    assert changes[1]["ok"] and changes[1]["ref"] == "pos[2]", changes
    assert changes[2]["ok"] and changes[2]["ref"] == "pos[2]", changes
    assert changes[3] == {}, changes
    patched = answers(outputs[2][:outputs[2].index("event:")])[0]
    assert patched["dropped"] == ["pos"] and patched["refs"]["pos[2]"]["task"] == "main", patched
    assert "event: values" in outputs[2] and '"speed":2.5' in outputs[2], outputs[2]
    assert '"pos[2]":' in outputs[2] and '"q":"good"' in outputs[2], outputs[2]
    events = answers(outputs[3])[0]["events"]
    assert events and all(e["kind"] == "hmi-write" for e in events), events
    assert "speed := 2.5 m/s (by alice)" in events[-1]["message"] and events[-1]["client"].startswith("127.0.0.1:"), events
    srv.stop()
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
