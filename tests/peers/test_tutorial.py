"""docs/tutorial.md, run as a newcomer would run it: every project file the
page builds, every command it shows, every output it prints.

The page is read from top to bottom:

- a ```yaml block right after `<!-- append: FILE -->` is added to FILE (in
  projects/tutorial_conveyor/, blocks joined by one blank line, as the page
  tells the reader to type them); both files start empty;
- every ```console block is run: a line `$ COMMAND` runs COMMAND (only
  `build/syncplc ...` and `mbpoll ...`) against the files as the page has
  built them so far, in a scratch copy of the tree; `# exit status N` after
  it is the status it must end with (default 0); the lines below it are what
  it must print (stdout, then stderr), `...` standing for lines left out;
- `$ build/syncplc run ...` starts in the background (the reader's first
  terminal), with `--modbus-port 0` added so the test takes a free port; its
  lines are what it prints on stderr when it starts;
- `^C` stops it with SIGINT (the reader's Ctrl-C); the lines below are what
  it prints on stdout, its Modbus counters compared as numbers.

The page's port 5020 becomes the port the server got. Between two mbpoll
runs the test waits PACE seconds, as a person typing does; a read whose
output is not the page's yet (a write is applied at the task's next scan) is
repeated for up to peerlib.ECHO_TIMEOUT s, and the repetitions are added to
the counters the page shows. At the end the files the page built must be
projects/tutorial_conveyor/ byte for byte, so the page quotes them exactly.

    /usr/bin/python3 tests/peers/test_tutorial.py build/syncplc
"""

import difflib
import os
import re
import shlex
import signal
import subprocess
import sys
import tempfile
import threading
import time

import peerlib as P

ROOT = os.path.dirname(os.path.dirname(P.HERE))
PAGE = os.path.join(ROOT, "docs", "tutorial.md")
PROJECT_DIR = os.path.join("projects", "tutorial_conveyor")
PAGE_PORT = "5020"
MBPOLL = "/usr/bin/mbpoll"
# A person takes seconds between two commands; a quarter of a second keeps a
# button's press and release more than one 10 ms scan apart.
PACE = 0.25


class PageError(AssertionError):
    pass


def parse_page(text):
    """[("append", file, body, line) | ("console", [lines], line)] in page order."""
    lines = text.split("\n")
    items = []
    pending = None
    i = 0
    while i < len(lines):
        line = lines[i]
        m = re.fullmatch(r"<!-- append: (\S+) -->", line.strip())
        if m:
            pending = (m.group(1), i + 1)
            i += 1
            continue
        m = re.fullmatch(r"```(\w*)", line)
        if m:
            j = i + 1
            while j < len(lines) and lines[j] != "```":
                j += 1
            if j == len(lines):
                raise PageError("tutorial.md:%d: code block never closed" % (i + 1))
            body = lines[i + 1:j]
            if pending:
                if m.group(1) != "yaml":
                    raise PageError("tutorial.md:%d: <!-- append --> must precede a ```yaml block" % pending[1])
                items.append(("append", pending[0], "\n".join(body) + "\n", i + 1))
                pending = None
            elif m.group(1) == "console":
                items.append(("console", body, i + 2))
            i = j + 1
            continue
        if pending and line.strip():
            raise PageError("tutorial.md:%d: <!-- append --> not followed by a code block" % pending[1])
        i += 1
    return items


def split_console(body, first_line):
    """A console block's steps: (kind, command or None, expected lines, page line)."""
    steps = []
    for n, line in enumerate(body):
        if line.startswith("$ "):
            steps.append(["cmd", line[2:], [], first_line + n])
        elif line == "^C":
            steps.append(["ctrl-c", None, [], first_line + n])
        elif steps:
            steps[-1][2].append(line)
        elif line.strip():
            raise PageError("tutorial.md:%d: output before any command" % (first_line + n))
    return steps


def norm(line):
    return " ".join(line.split())


def check_output(expected, actual, where, placeholders=()):
    """The page's lines must be the actual ones: groups between `...` appear in
    order and each group as consecutive lines; without a leading/trailing
    `...` the output starts/ends there. Blank lines are not compared."""
    def clean(lines):
        out = []
        for l in lines:
            l = norm(l)
            for pattern, name in placeholders:
                if re.search(pattern, l):
                    l = name
            if l:
                out.append(l)
        return out

    exp = clean(expected)
    act = clean(actual.split("\n"))
    groups, cur = [], []
    for l in exp:
        if l == "...":
            groups.append(cur)
            cur = []
        else:
            cur.append(l)
    groups.append(cur)
    anchored_start = not exp or exp[0] != "..."
    anchored_end = not exp or exp[-1] != "..."
    pos = 0
    ok = True
    for gi, g in enumerate(groups):
        if not g:
            continue
        found = None
        last_start = len(act) - len(g)
        for s in range(pos, last_start + 1):
            if act[s:s + len(g)] == g:
                found = s
                break
            if gi == 0 and anchored_start:
                break
        if found is None:
            ok = False
            break
        pos = found + len(g)
    if ok and anchored_end and groups[-1] and pos != len(act):
        ok = False
    if not ok:
        raise AssertionError("%s: the output is not what the page shows\n--- page:\n%s\n--- actual:\n%s"
                             % (where, "\n".join(expected), actual))


def mbpoll_writes(argv):
    """True when the mbpoll command writes (values after the host)."""
    if "127.0.0.1" not in argv:
        raise PageError("mbpoll without the host 127.0.0.1: %s" % " ".join(argv))
    return any(a != "--" for a in argv[argv.index("127.0.0.1") + 1:])


class Tutorial:
    def __init__(self, binary, scratch):
        self.binary = binary
        self.scratch = scratch
        self.files = {}        # file name -> [block, ...]
        self.run = None        # the background `syncplc run`
        self.run_err = []
        self.port = None
        self.extra_reads = 0   # repeated mbpoll reads the page does not show
        self.last_mbpoll = 0.0
        os.makedirs(os.path.join(scratch, PROJECT_DIR))
        for name in ("conveyor.yaml", "tests.yaml"):
            self.write(name, [])

    def write(self, name, blocks):
        self.files[name] = blocks
        with open(os.path.join(self.scratch, PROJECT_DIR, name), "w") as f:
            f.write("\n".join(blocks))

    def append(self, name, body):
        if name not in self.files:
            raise PageError("the page appends to %s, which the tutorial does not have" % name)
        self.write(name, self.files[name] + [body])

    def command(self, text, expected, line):
        where = "tutorial.md:%d: $ %s" % (line, text)
        m = re.fullmatch(r"(.*?)\s+# exit status (\d+)", text)
        status = 0
        if m:
            text, status = m.group(1), int(m.group(2))
        argv = shlex.split(text)
        if argv[0] == "build/syncplc":
            argv[0] = self.binary
            if argv[1] == "run":
                return self.start_run(argv, expected, where)
        elif argv[0] == "mbpoll":
            return self.mbpoll(argv, expected, status, where)
        else:
            raise PageError("%s: the test runs only build/syncplc and mbpoll" % where)
        r = subprocess.run(argv, cwd=self.scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=120)
        out = r.stdout + r.stderr
        if r.returncode != status:
            raise AssertionError("%s: exit status %d, the page says %d\n%s" % (where, r.returncode, status, out))
        check_output(expected, out, where)
        print("ok  %s" % where)

    def start_run(self, argv, expected, where):
        if self.run:
            raise PageError("%s: a second syncplc run" % where)
        argv = argv + ["--modbus-port", "0"]
        self.run = subprocess.Popen(argv, cwd=self.scratch, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    text=True)
        P._running.append(self.run)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            line = self.run.stderr.readline()
            if not line:
                break
            self.run_err.append(line)
            m = re.search(r"modbus: listening on 127\.0\.0\.1:(\d+) ", line)
            if m:
                self.port = int(m.group(1))
                break
        if self.port is None:
            self.run.kill()
            out, err = self.run.communicate()
            raise AssertionError("%s: no Modbus port reported\n%s%s%s" % (where, "".join(self.run_err), err, out))
        started = "".join(self.run_err)  # what it printed up to the port (warnings may follow when not root)
        threading.Thread(target=lambda: self.run_err.extend(self.run.stderr), daemon=True).start()
        check_output([self.page_port(l) for l in expected], started, where)
        print("ok  %s (port %d)" % (where, self.port))

    def page_port(self, line):
        return line.replace("127.0.0.1:" + PAGE_PORT, "127.0.0.1:%d" % self.port)

    def mbpoll(self, argv, expected, status, where):
        if self.port is None:
            raise PageError("%s: mbpoll before syncplc run" % where)
        if "-p" not in argv or argv[argv.index("-p") + 1] != PAGE_PORT:
            raise PageError("%s: mbpoll without -p %s" % (where, PAGE_PORT))
        argv = list(argv)  # argv[0] stays "mbpoll": it names itself in its messages
        argv[argv.index("-p") + 1] = str(self.port)
        deadline = time.monotonic() + P.ECHO_TIMEOUT
        tries = 0
        while True:
            time.sleep(max(0.0, self.last_mbpoll + PACE - time.monotonic()))
            r = subprocess.run(argv, executable=MBPOLL, cwd=self.scratch, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=60)
            self.last_mbpoll = time.monotonic()
            tries += 1
            out = r.stdout + r.stderr
            try:
                if r.returncode != status:
                    raise AssertionError("%s: exit status %d, the page says %d\n%s" % (where, r.returncode, status, out))
                check_output([self.page_port(l) for l in expected], out, where)
                break
            except AssertionError:
                # Only a read that may be early is tried again; a write happens once.
                if mbpoll_writes(argv) or status != 0 or time.monotonic() > deadline:
                    raise
        self.extra_reads += tries - 1
        print("ok  %s%s" % (where, " (read %d times)" % tries if tries > 1 else ""))

    def ctrl_c(self, expected, where):
        if not self.run:
            raise PageError("%s: ^C without syncplc run" % where)
        time.sleep(PACE)  # the server has seen the last client close
        self.run.send_signal(signal.SIGINT)
        try:
            out = self.run.stdout.read()
            rc = self.run.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.run.kill()
            raise AssertionError("%s: syncplc run did not stop within 60 s of SIGINT" % where)
        err = "".join(self.run_err)
        if rc != 0:
            raise AssertionError("%s: syncplc run exited with status %d\n%s\n%s" % (where, rc, out, err))
        for bad in ("ERROR: AddressSanitizer", "runtime error:", "WARNING: ThreadSanitizer"):
            if bad in err:
                raise AssertionError("sanitizer report on stderr:\n" + err)
        expected = [self.page_port(l) for l in expected]
        counters = ((P.Counters.LINE1.pattern, "<requests line>"), (P.Counters.LINE2.pattern, "<connections line>"))
        check_output(expected, out, where, counters)
        got, want = P.Counters(out), P.Counters("\n".join(expected))
        n = self.extra_reads
        problems = []
        for what, g, w in (("requests", got.requests, want.requests + n),
                           ("exceptions by code", got.by_code, want.by_code),
                           ("values written", got.values_written, want.values_written),
                           ("connections accepted", got.accepted, want.accepted + n),
                           ("refused", got.refused, want.refused),
                           ("closed by the client or still open", got.closed_by_client + got.open,
                            want.closed_by_client + want.open + n),
                           ("closed for a bad frame", got.closed_bad_frame, want.closed_bad_frame),
                           ("closed idle", got.closed_idle, want.closed_idle),
                           ("closed not reading", got.closed_not_reading, want.closed_not_reading)):
            if g != w:
                problems.append("%s: %r, the page says %r (with %d repeated reads)" % (what, g, w, n))
        if problems:
            raise AssertionError("%s: the counters differ from the page's:\n  %s\n%s"
                                 % (where, "\n  ".join(problems), out))
        self.run = None
        print("ok  %s (%d repeated reads added to the page's counters)" % (where, n))

    def compare_files(self):
        for name in sorted(self.files):
            built = "\n".join(self.files[name])
            with open(os.path.join(ROOT, PROJECT_DIR, name)) as f:
                repo = f.read()
            if built != repo:
                diff = "".join(difflib.unified_diff(repo.splitlines(True), built.splitlines(True),
                                                    os.path.join(PROJECT_DIR, name), "what tutorial.md builds"))
                raise AssertionError("the page does not quote %s exactly:\n%s" % (name, diff))
            print("ok  %s is what the page builds" % os.path.join(PROJECT_DIR, name))


def main():
    binary = os.path.abspath(P.syncplc_binary())
    if not os.access(MBPOLL, os.X_OK):
        sys.exit("mbpoll is not installed (scripts/setup.sh installs it)")
    with open(PAGE) as f:
        items = parse_page(f.read())
    with tempfile.TemporaryDirectory(prefix="syncplc_tutorial_") as scratch:
        t = Tutorial(binary, scratch)
        try:
            commands = 0
            for item in items:
                if item[0] == "append":
                    t.append(item[1], item[2])
                    continue
                for kind, text, expected, line in split_console(item[1], item[2]):
                    commands += 1
                    if kind == "cmd":
                        t.command(text, expected, line)
                    else:
                        t.ctrl_c(expected, "tutorial.md:%d: ^C" % line)
            if t.run:
                raise PageError("the page leaves syncplc run running (no ^C)")
            t.compare_files()
        finally:
            if t.run and t.run.poll() is None:
                t.run.kill()
    if commands < 10:
        raise PageError("only %d commands found in the page" % commands)
    print("test_tutorial: OK (%d commands of docs/tutorial.md)" % commands)


if __name__ == "__main__":
    sys.exit(main())
