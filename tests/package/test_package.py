"""The Debian package and its systemd unit (packaging/, docs/deployment.md).

cpack makes the package from the build tree's binary as it is (nothing is
rebuilt); its control fields (Depends names the package of every shared
library the binary loads) and its contents; `systemd-analyze verify` on its
unit and the unit's restart policy against the exit statuses of
runtime/cli/commands.hpp. Then the package is installed with
`apt-get install ./syncplc_*.deb` when the test runs as root and
SYNCPLC_TEST_INSTALL=1 (scripts/test.sh), else extracted with `dpkg-deb -x`;
and the unit's ExecStart line, as written, runs with the environment
systemd gives the service (STATE_DIRECTORY, RUNTIME_DIRECTORY, the unit's
Environment=; SYNCPLC_OPTIONS set as `systemctl edit` would, for a free HTTP
port), as the unit's user when installed: first on an empty database (status
2, which the unit does not restart on), then on one a first `syncplc run
PROJECT` put a boot project into (the admin's first steps), until
/api/v1/status answers with that project and / serves the installed HMI.
A machine without systemd as PID 1 cannot start the unit itself.

Usage: /usr/bin/python3 tests/package/test_package.py BUILD_DIR SOURCE_DIR
Exit status 77 (skipped): hmi_web/dist is not built (scripts/build_hmi.sh).
"""

import glob
import json
import os
import pwd
import re
import resource
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

SKIP = 77
# Only a guard against a hang: every wait below waits for a condition.
GUARD_S = 120.0

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        failures.append(what)
    return cond


def run(cmd, **kw):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)
    return p.returncode, p.stdout


def exit_codes(source):
    """The kExit* constants of runtime/cli/commands.hpp."""
    text = open(os.path.join(source, "runtime/cli/commands.hpp")).read()
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"constexpr int (kExit\w+) = (\d+);", text)}


def deb_fields(deb):
    rc, out = run(["dpkg-deb", "--field", deb])
    assert rc == 0, out
    fields, key = {}, None
    for line in out.splitlines():
        if line.startswith(" ") and key:
            fields[key] += "\n" + line
        elif ":" in line:
            key, value = line.split(":", 1)
            fields[key] = value.strip()
    return fields


def depends_names(depends):
    """'libc6 (>= 2.34), libfmt9 (>= 9.1.0+ds1), a | b' -> {'libc6', 'libfmt9', 'a', 'b'}"""
    names = set()
    for part in re.split(r"[,|]", depends):
        part = part.strip()
        if part:
            names.add(re.split(r"[\s(:]", part)[0])
    return names


def owning_package(lib):
    """The installed package a shared library's file belongs to (merged /usr:
    dpkg knows it by one of its two names)."""
    candidates = [lib, os.path.realpath(lib)]
    for c in list(candidates):
        if c.startswith("/usr/"):
            candidates.append(c[len("/usr"):])
        else:
            candidates.append("/usr" + c)
    for c in candidates:
        rc, out = run(["dpkg-query", "-S", c])
        if rc == 0:
            return out.split(":", 1)[0].split(",")[0].strip()
    return None


def unit_service_section(path):
    """The [Service] section's assignments, in order (Environment= may repeat)."""
    section, entries = None, []
    for raw in open(path):
        line = raw.strip()
        if not line or line[0] in "#;":
            continue
        if line.startswith("["):
            section = line
            continue
        if section == "[Service]":
            key, value = line.split("=", 1)
            entries.append((key.strip(), value.strip()))
    return entries


def systemd_environment(entries):
    env = {}
    for key, value in entries:
        if key == "Environment":
            for word in split_words(value):
                name, _, v = word.partition("=")
                env[name] = v
    return env


def split_words(text):
    """systemd's splitting of a command line: whitespace, double and single quotes."""
    words, cur, quote, have = [], "", None, False
    i = 0
    while i < len(text):
        c = text[i]
        if quote:
            if c == quote:
                quote = None
            elif c == "\\" and i + 1 < len(text):
                i += 1
                cur += text[i]
            else:
                cur += c
        elif c in "\"'":
            quote, have = c, True
        elif c.isspace():
            if cur or have:
                words.append(cur)
            cur, have = "", False
        elif c == "\\" and i + 1 < len(text):
            i += 1
            cur += text[i]
        else:
            cur += c
        i += 1
    if cur or have:
        words.append(cur)
    return words


def expand_exec(line, env):
    """ExecStart= as systemd expands it (systemd.service(5), "Command lines"):
    a word that is exactly $NAME becomes the variable's value split at
    whitespace (zero or more words); ${NAME} is replaced inside its word."""
    argv = []
    for word in split_words(line):
        m = re.fullmatch(r"\$([A-Za-z_][A-Za-z0-9_]*)", word)
        if m:
            argv.extend(env.get(m.group(1), "").split())
            continue
        argv.append(re.sub(r"\$\{([A-Za-z_][A-Za-z0-9_]*)\}", lambda k: env.get(k.group(1), ""), word))
    return argv


def rlimit_value(text):
    return resource.RLIM_INFINITY if text == "infinity" else int(text)


UNIT_LIMITS = (("LimitRTPRIO", resource.RLIMIT_RTPRIO), ("LimitMEMLOCK", resource.RLIMIT_MEMLOCK))


def can_set_limits(settings):
    """Whether this process may raise its hard limits to the unit's (it needs
    CAP_SYS_RESOURCE, which systemd has and a container's root may not)."""
    code = "import resource\n" + "".join(
        "resource.setrlimit(%d, (%d, %d))\n" % (which, rlimit_value(settings[key]), rlimit_value(settings[key]))
        for key, which in UNIT_LIMITS)
    return subprocess.run([sys.executable, "-c", code], stderr=subprocess.DEVNULL).returncode == 0


def as_service(user, settings, limits):
    """A child's start as systemd gives it: LimitRTPRIO= and LimitMEMLOCK=
    (when `limits`), then User= and Group= with no other groups."""
    def start():
        for key, which in UNIT_LIMITS if limits else ():
            v = rlimit_value(settings[key])
            resource.setrlimit(which, (v, v))
        os.setgroups([])
        os.setgid(user.pw_gid)
        os.setuid(user.pw_uid)
    return start


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(url):
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()
    except (urllib.error.URLError, ConnectionError, socket.timeout):
        return None, b""


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: /usr/bin/python3 %s BUILD_DIR SOURCE_DIR" % sys.argv[0])
    build, source = (os.path.abspath(a) for a in sys.argv[1:])
    if not os.path.isfile(os.path.join(source, "hmi_web/dist/index.html")):
        print("skipped: hmi_web/dist is not built (scripts/build_hmi.sh); the package needs it")
        return SKIP
    codes = exit_codes(source)
    # A syncplc already installed on this machine is left alone: extracted then.
    was_installed = run(["dpkg-query", "-W", "-f=${Status}", "syncplc"])[1].startswith("install ok installed")
    install = os.geteuid() == 0 and os.environ.get("SYNCPLC_TEST_INSTALL") == "1" and not was_installed
    tmp = tempfile.mkdtemp(prefix="syncplc-package-")
    os.chmod(tmp, 0o755)  # the unit's user reads the project from here
    installed_here = False
    try:
        # 1. The package, from the build tree's binary.
        rc, out = run(["cpack", "-G", "DEB", "--config", os.path.join(build, "CPackConfig.cmake"),
                       "-B", os.path.join(tmp, "out")])
        debs = glob.glob(os.path.join(tmp, "out", "syncplc_*.deb"))
        if not check(rc == 0 and len(debs) == 1, "cpack -G DEB made one syncplc_*.deb"):
            print(out)
            return 1
        deb = debs[0]
        print("package:", os.path.basename(deb), os.path.getsize(deb), "bytes")

        # 2. Control fields: Depends has the package of every library the binary loads.
        fields = deb_fields(deb)
        print("Depends:", fields.get("Depends", ""))
        check(fields.get("Package") == "syncplc", "Package: syncplc")
        deps = depends_names(fields.get("Depends", ""))
        check("adduser" in deps, "Depends names adduser (the postinst's system user)")
        check("procps" in deps, "Depends names procps (the unit's ExecReload=/bin/kill)")
        # The libraries the binary names itself (DT_NEEDED; theirs are their
        # packages' dependencies), where the loader finds them.
        binary = os.path.join(build, "syncplc")
        rc, out = run(["readelf", "-d", binary])
        needed = set(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out))
        rc, out = run(["ldd", binary])
        found = dict(re.findall(r"^\s*(\S+) => (/\S+)", out, re.M))
        libs = [found[n] for n in sorted(needed) if n in found]
        check(len(libs) == len(needed) >= 5, "the binary's %d shared libraries are found" % len(needed))
        for lib in libs:
            pkg = owning_package(lib)
            check(pkg is not None and pkg in deps, "Depends names %s (for %s)" % (pkg, os.path.basename(lib)))

        # 3. Contents.
        rc, out = run(["dpkg-deb", "--contents", deb])
        paths = {line.split()[-1].lstrip(".") for line in out.splitlines() if line.strip()}
        for p in ("/usr/bin/syncplc", "/usr/lib/systemd/system/syncplc.service", "/usr/share/doc/syncplc/blocks.md",
                  "/usr/share/doc/syncplc/deployment.md", "/usr/share/syncplc/hmi/index.html",
                  "/usr/lib/udev/rules.d/60-syncplc.rules"):
            check(p in paths, "the package holds " + p)
        rc, out = run(["sh", "-c", "dpkg-deb --ctrl-tarfile '%s' | tar -t" % deb])
        for script in ("postinst", "prerm", "postrm"):
            check(("./" + script) in out.split(), "the package has a " + script)

        # 4. Installed (apt resolves the dependencies) or extracted.
        if install:
            rc, out = run(["apt-get", "install", "-y", "--no-install-recommends", deb],
                          env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"))
            installed_here = rc == 0
            if not check(rc == 0, "apt-get install -y %s" % deb):
                print(out)
                return 1
            root = "/"
            user = pwd.getpwnam("syncplc")
            check(True, "the postinst made the system user syncplc (uid %d)" % user.pw_uid)
        else:
            root = os.path.join(tmp, "root")
            rc, out = run(["dpkg-deb", "-x", deb, root])
            check(rc == 0, "dpkg-deb -x (not installed: not root, SYNCPLC_TEST_INSTALL unset, or syncplc installed already)")
            user = None
        unit = os.path.join(root, "usr/lib/systemd/system/syncplc.service")

        # 5. The unit: systemd-analyze verify, and its restart policy against the exit statuses.
        verified = unit
        if not install:
            # verify checks that ExecStart's binary is there: for an extracted
            # package, a copy of the unit names the extracted binary (as the
            # run below does; --root would hide the system's targets and /bin/kill).
            os.makedirs(os.path.join(tmp, "verify"))
            verified = os.path.join(tmp, "verify", "syncplc.service")
            with open(verified, "w") as f:
                f.write(open(unit).read().replace("=/usr/bin/syncplc ", "=%s/usr/bin/syncplc " % root))
        verify = ["systemd-analyze", "verify", verified]
        rc, out = run(verify)
        if not check(rc == 0, " ".join(verify)):
            print(out)
        elif out.strip():
            print(out)
        entries = unit_service_section(unit)
        settings = dict(entries)
        check(settings.get("Restart") == "on-failure", "Restart=on-failure")
        no_restart = {int(s) for s in settings.get("RestartPreventExitStatus", "").split()}
        check(no_restart == {codes["kExitInvalid"]},
              "RestartPreventExitStatus is kExitInvalid (%d) alone" % codes["kExitInvalid"])
        for name in ("kExitWatchdogStopped", "kExitHungScan", "kExitDriverFailed"):
            check(codes[name] not in no_restart, "%s (%d) restarts" % (name, codes[name]))
        check(settings.get("LimitMEMLOCK") == "infinity", "LimitMEMLOCK=infinity")
        check(int(settings.get("LimitRTPRIO", "0")) >= 50, "LimitRTPRIO allows the tasks' priorities")
        check(settings.get("User") == "syncplc", "User=syncplc")

        # 6. The ExecStart line, as written, with the environment systemd gives it.
        exec_line = settings["ExecStart"]
        check(exec_line[0] not in "-@+!:", "ExecStart= has no prefix the test would have to mimic")
        state = os.path.join(tmp, "state")      # systemd: StateDirectory=syncplc -> /var/lib/syncplc
        runtime = os.path.join(tmp, "runtime")  # systemd: RuntimeDirectory=syncplc -> /run/syncplc
        for d in (state, runtime):
            os.makedirs(d, mode=0o700)
            if user:
                os.chown(d, user.pw_uid, user.pw_gid)
        port = free_port()
        env = {"PATH": "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin", "LANG": "C.UTF-8",
               "HOME": state, "STATE_DIRECTORY": state, "RUNTIME_DIRECTORY": runtime}
        env.update(systemd_environment(entries))
        # The documented override (docs/deployment.md): `systemctl edit syncplc`, Environment=SYNCPLC_OPTIONS=...
        env["SYNCPLC_OPTIONS"] = "--http 127.0.0.1:%d" % port
        argv = expand_exec(exec_line, env)
        print("ExecStart:", " ".join(argv))
        check(argv[0] == "/usr/bin/syncplc", "ExecStart runs /usr/bin/syncplc")
        if not install:
            argv[0] = os.path.join(root, argv[0].lstrip("/"))  # the extracted copy
        # Installed: as the unit's user with the unit's limits, as systemd
        # starts it (the limits set while still root, then the user).
        limits = bool(user) and can_set_limits(settings)
        if user and not limits:
            print("note: this process may not raise its limits (no CAP_SYS_RESOURCE): the service runs with "
                  "the test's own, and whether the unit's give it SCHED_FIFO and locked memory is not checked")
        as_user = {"preexec_fn": as_service(user, settings, limits)} if user else {}

        # 6a. No boot project yet: status 2, on which the unit does not restart.
        rc, out = run(argv, env=env, **as_user)
        check(rc == codes["kExitInvalid"] and "no database" in out,
              "without a boot project ExecStart exits %d (not restarted): %s" % (rc, out.strip()))

        # 6b. The admin's first step: a first run of the project puts it into the database.
        project_dir = os.path.join(tmp, "project")
        os.makedirs(project_dir)
        shutil.copy(os.path.join(source, "tests/package/boot.yaml"), project_dir)
        os.chmod(os.path.join(project_dir, "boot.yaml"), 0o644)
        first = [argv[0], "run", os.path.join(project_dir, "boot.yaml"), "--db", os.path.join(state, "plc.db"),
                 "--duration", "0.2s", "--no-status", "--http", "off"]
        rc, out = run(first, env=env, **as_user)
        if not check(rc == 0, "first run: " + " ".join(first)):
            print(out)
            return 1

        # 6c. The unit's line starts the boot project; /api/v1/status answers.
        log = open(os.path.join(tmp, "service.log"), "w+")
        proc = subprocess.Popen(argv, env=env, stdout=log, stderr=subprocess.STDOUT, **as_user)
        status, body = None, b""
        deadline = time.monotonic() + GUARD_S
        while proc.poll() is None and time.monotonic() < deadline:
            status, body = get("http://127.0.0.1:%d/api/v1/status" % port)
            if status == 200:
                break
            time.sleep(0.1)
        ok = check(status == 200, "GET /api/v1/status answers 200")
        if ok:
            doc = json.loads(body)
            check(doc["runtime"]["program"] == "package_boot", "the service runs the boot project package_boot")
            check(doc["tasks"] and doc["tasks"][0]["name"] == "main", "its task main is listed")
            index = open(os.path.join(root, "usr/share/syncplc/hmi/index.html"), "rb").read()
            st, page = get("http://127.0.0.1:%d/" % port)
            check(st == 200 and page == index, "GET / serves the installed HMI's index.html")
            check(os.path.isfile(os.path.join(runtime, "syncplc.pid")), "the pid file is in RUNTIME_DIRECTORY")
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)  # what systemctl stop sends
        try:
            rc = proc.wait(timeout=GUARD_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            rc = proc.wait()
        log.seek(0)
        text = log.read()
        check(rc == 0, "SIGTERM stops it with status 0 (got %s)" % rc)
        check("starting version 1 of %s/plc.db" % state in text, "it started version 1 of the state directory's plc.db")
        if limits:
            # The unit's limits are what an unprivileged service needs for
            # SCHED_FIFO at the project's priority (50) and mlockall.
            check("SCHED_FIFO" not in text, "as the user syncplc with the unit's limits the task got SCHED_FIFO")
            check("mlockall failed" not in text, "... and its memory locked")
        if failures:
            print(text)
    finally:
        if installed_here:
            rc, out = run(["apt-get", "purge", "-y", "syncplc"], env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"))
            check(rc == 0, "apt-get purge -y syncplc (the test installed it)")
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
