"""HTTPS: `syncplc run --http-cert --http-key` with a self-signed certificate
made by the openssl command, read with Python's ssl module trusting it; plain
HTTP on that port gets no answer; listening beyond loopback without TLS, or
with a key that does not load, refuses to start with the reason.

    /usr/bin/python3 tests/peers/test_http_tls.py build/syncplc
"""

import http.client
import json
import os
import ssl
import subprocess

import peerlib

BINARY = peerlib.syncplc_binary()


def main():
    d = peerlib.STATE_DIR
    cert, key = os.path.join(d, "cert.pem"), os.path.join(d, "key.pem")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", key, "-out", cert,
                    "-days", "2", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
                   check=True, capture_output=True, timeout=120)
    srv = peerlib.Server(BINARY, peerlib.project("http_api.yaml"),
                         extra=["--http", "127.0.0.1:0", "--http-cert", cert, "--http-key", key, "--db", ":memory:"])
    port = srv.http_port("https")

    ctx = ssl.create_default_context(cafile=cert)
    c = http.client.HTTPSConnection("127.0.0.1", port, context=ctx, timeout=30)
    c.request("GET", "/api/v1/status")
    r = c.getresponse()
    assert r.status == 200, r.status
    assert json.loads(r.read())["runtime"]["http"] == "https://127.0.0.1:%d/" % port
    c.close()
    # Without trusting the certificate, the client refuses it (it is verified).
    try:
        c = http.client.HTTPSConnection("127.0.0.1", port, context=ssl.create_default_context(), timeout=30)
        c.request("GET", "/api/v1/status")
        raise AssertionError("an untrusted certificate was accepted")
    except ssl.SSLCertVerificationError:
        pass
    # Plain HTTP to the TLS port: no HTTP answer.
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        c.request("GET", "/api/v1/status")
        r = c.getresponse()
        raise AssertionError("plain HTTP answered on the HTTPS port: %d" % r.status)
    except (http.client.HTTPException, ConnectionError, OSError):
        pass
    srv.stop()

    def refused(extra, words):
        p = subprocess.run([BINARY, "run", peerlib.project("http_api.yaml"), "--no-status", "-d", "5s", "--db", ":memory:",
                            *extra], capture_output=True, text=True, timeout=60)
        assert p.returncode == 2 and words in p.stderr, (extra, p.returncode, p.stderr)
    refused(["--http", "0.0.0.0:0"], "needs HTTPS")
    refused(["--http", "127.0.0.1:0", "--http-cert", cert, "--http-key", cert], "cannot load the certificate")
    refused(["--http", "127.0.0.1:0", "--http-cert", cert], "both --http-cert and --http-key")
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
