"""The PLCopen axes over HTTP (docs/http-api.md, "Axes"), with curl against a
real `syncplc run` of tests/web/axes_api.yaml. Checked:

- GET /api/v1/axes lists every MC_AXIS with its PLCopen state, unit, the
  active command and the block that gave it, power, quality and age; a pin
  wired to an hmi: none tag is null for an anonymous reader;
- no login: 401; a viewer's enable, an operator's reset: 403; an unknown
  axis: 404; a body that is not JSON: 415;
- reset of an axis not in ErrorStop: 409 with the state named;
- disable (operator): the axis goes Disabled while its MC_Power still asks,
  the move it ran is aborted; enable: MC_Power powers it again and the
  program's move resumes;
- enable of an axis whose program does not ask for power leaves it Disabled;
- a wired permissive is refused (409);
- a drive fault: ErrorStop 0x0301 with its text; reset (engineer) with the
  fault gone: Standstill, then the program's move again;
- every command is in the event log with its user.

Waits are for conditions; times only guard against a hang.

    /usr/bin/python3 tests/web/test_axes_api.py build/syncplc
"""

import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "peers"))

import peerlib  # noqa: E402  (syncplc run on free ports)

GUARD = 60  # s, only against a hang
PASSWORDS = {"viewer": "viewer-pw-1", "operator": "operator-pw-1", "engineer": "engineer-pw-1"}


def curl(url, method="GET", body=None, token=None, content_type="application/json"):
    """(status, JSON) of one request made by curl."""
    args = ["curl", "-sS", "-X", method, "-o", "-", "-w", "\n%{http_code}", url]
    if token:
        args += ["-H", "Authorization: Bearer " + token]
    if body is not None:
        args += ["-H", "Content-Type: " + content_type, "--data-binary", body if isinstance(body, str) else json.dumps(body)]
    p = subprocess.run(args, capture_output=True, text=True, timeout=GUARD)
    if p.returncode != 0:
        raise AssertionError("curl %s %s failed: %s" % (method, url, p.stderr))
    text, _, status = p.stdout.rpartition("\n")
    return int(status), (json.loads(text) if text.strip() else None)


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print("ok  " + what)


def main():
    binary = peerlib.syncplc_binary()
    tmp = tempfile.mkdtemp(prefix="syncplc-axes-api-")
    db = os.path.join(tmp, "plc.db")
    for user, password in PASSWORDS.items():
        peerlib.add_user(binary, db, user, user, password)
    server = peerlib.Server(binary, os.path.join(HERE, "axes_api.yaml"), extra=("--db", db, "--http", "127.0.0.1:0"))
    base = "http://127.0.0.1:%d/api/v1" % server.http_port()
    try:
        tokens = {}
        for user, password in PASSWORDS.items():
            status, j = curl(base + "/login", "POST", {"user": user, "password": password})
            check(status == 200, "login " + user)
            tokens[user] = j["token"]

        def axes():
            status, j = curl(base + "/axes")
            assert status == 200, (status, j)
            return {a["name"]: a for a in j["axes"]}

        def wait(what, pred):
            end = time.monotonic() + GUARD
            while True:
                a = axes()
                if pred(a):
                    check(True, what)
                    return a
                if time.monotonic() > end:
                    raise AssertionError("timed out waiting for %s: %s" % (what, json.dumps(a, indent=1)))
                time.sleep(0.01)

        a = wait("x runs its program's MC_MoveVelocity", lambda a: a["x"]["state"] == "ContinuousMotion")
        check(sorted(a) == ["x", "y", "z"], "GET /axes lists the three MC_AXIS instances: %s" % sorted(a))
        x = a["x"]
        check(x["task"] == "motion" and x["period_ns"] == 2000000, "x: its task and period")
        check(x["unit"] == "mm", "x: the unit of the tag its position is wired to")
        check(a["y"]["unit"] == "u", "y: user units when no tag says")
        check(x["command"] == "MoveVelocity" and x["command_block"] == "x_move", "x: the active command and its block")
        check(x["powered"] is True and x["error_id"] == 0 and x["error"] == "", "x: powered, no error")
        check(x["quality"]["q"] == "good" and x["quality"]["age_ns"] >= 0, "x: quality good, with its age")
        check(a["y"]["state"] == "Disabled" and a["y"]["command"] is None and a["y"]["command_block"] is None,
              "y: Disabled, no command")
        check(a["z"]["hmi_enable_wired"] is True and x["hmi_enable_wired"] is False, "z's permissive is wired, x's not")
        check(a["z"]["hmi_enable"] is None and a["z"]["state"] == "Standstill",
              "z is shown, its permissive null: wired to an hmi: none tag, not for anonymous readers")

        # Refusals.
        status, j = curl(base + "/axes/x/disable", "POST", {})
        check(status == 401, "disable without a login: 401")
        status, j = curl(base + "/axes/x/disable", "POST", {}, tokens["viewer"])
        check(status == 403 and "operator" in j["error"], "disable as a viewer: 403 naming the role needed")
        status, j = curl(base + "/axes/x/reset", "POST", {}, tokens["operator"])
        check(status == 403 and "engineer" in j["error"], "reset as an operator: 403 naming the role needed")
        status, j = curl(base + "/axes/nope/disable", "POST", {}, tokens["operator"])
        check(status == 404 and "nope" in j["error"], "an unknown axis: 404")
        status, j = curl(base + "/axes/x_move/disable", "POST", {}, tokens["operator"])
        check(status == 404, "an instance that is no MC_AXIS: 404")
        status, j = curl(base + "/axes/x/disable", "POST", "{}", tokens["operator"], content_type="text/plain")
        check(status == 415, "a body that is not JSON: 415")
        status, j = curl(base + "/axes/x/reset", "POST", {}, tokens["engineer"])
        check(status == 409 and "ContinuousMotion" in j["error"] and "not ErrorStop" in j["error"],
              "reset outside ErrorStop: 409 naming the state")
        status, j = curl(base + "/axes/z/disable", "POST", {}, tokens["engineer"])
        check(status == 409 and "wired" in j["error"], "a wired permissive: 409")

        # Disable: Disabled while MC_Power still asks; the move is aborted.
        status, j = curl(base + "/axes/x/disable", "POST", {}, tokens["operator"])
        check(status == 200 and j["command"] == "disable", "disable x as an operator: 200")
        a = wait("x Disabled", lambda a: a["x"]["state"] == "Disabled")
        check(a["x"]["hmi_enable"] is False, "x's permissive is off")
        a = wait("x's power stage off", lambda a: a["x"]["powered"] is False)
        status, j = curl(base + "/values?refs=x_power.Enable")
        check(j["values"]["x_power.Enable"] is True, "x's MC_Power still asks for power")
        time.sleep(0.2)  # 100 scans: the program asks every scan, the axis stays down
        check(axes()["x"]["state"] == "Disabled", "x stays Disabled while the program asks")

        status, j = curl(base + "/axes/x/enable", "POST", {}, tokens["operator"])
        check(status == 200, "enable x: 200")
        wait("x powered again by its MC_Power and moving", lambda a: a["x"]["state"] == "ContinuousMotion")
        status, j = curl(base + "/axes/y/enable", "POST", {}, tokens["operator"])
        check(status == 200, "enable y: 200")
        time.sleep(0.2)
        check(axes()["y"]["state"] == "Disabled" and axes()["y"]["powered"] is False,
              "enable never powers y, whose program does not ask")

        # A drive fault, then the HMI's reset.
        status, j = curl(base + "/tags/fault", "PUT", {"value": True}, tokens["operator"])
        check(status == 200, "the drive of x faults")
        a = wait("x in ErrorStop", lambda a: a["x"]["state"] == "ErrorStop")
        check(a["x"]["error_id"] == 0x0301 and a["x"]["error"] == "the drive faulted", "error 0x0301 and its text")
        curl(base + "/tags/fault", "PUT", {"value": False}, tokens["operator"])
        wait("x stands in ErrorStop", lambda a: a["x"]["state"] == "ErrorStop" and a["x"]["velocity"] == 0)
        status, j = curl(base + "/axes/x/reset", "POST", {}, tokens["engineer"])
        check(status == 200 and j["state"] == "ErrorStop", "reset x as an engineer: 200")
        a = wait("x leaves ErrorStop", lambda a: a["x"]["state"] != "ErrorStop")
        check(a["x"]["error_id"] == 0, "the error is acknowledged")

        status, j = curl(base + "/events?kind=hmi-write&limit=50", token=tokens["engineer"])
        texts = [e["message"] for e in j["events"]]
        for want in ("x: disable (by operator)", "x: enable (by operator)", "x: reset (by engineer)"):
            check(any(want in t for t in texts), "event log: " + want)
    finally:
        server.stop()


if __name__ == "__main__":
    main()
