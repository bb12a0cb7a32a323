// Runs the built `syncplc` command for end-to-end tests: exit status, stdout
// and stderr of one invocation.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <linux/capability.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/test_blocks.hpp"

namespace syncplc::testing {

// Each test process gives the `syncplc run`s it starts a PLC database of its
// own (XDG_STATE_HOME, which they inherit): ctest runs test cases in parallel
// processes, and a second instance on one database is refused.
inline bool isolate_plc_state() {
  const std::string dir = "/tmp/syncplc-test-state/" + std::to_string(getpid());
  setenv("XDG_STATE_HOME", dir.c_str(), 1);
  return true;
}
inline const bool kPlcStateIsolated = isolate_plc_state();

// For a child about to exec `syncplc run` of a scan that never ends (a 1 h
// BURN): takes away its SCHED_FIFO permission (CAP_SYS_NICE out of the
// bounding set, so the exec'd program does not get it back), and the run
// falls back to normal priority with a warning, as for a user without rtprio.
// At SCHED_FIFO such a scan holds a whole core; two of these tests side by
// side under `ctest -j2` would leave everything else the 5 % of the CPU that
// real-time throttling keeps back, and a stop that takes 0.6 s takes 12.
inline void drop_realtime_priority() { prctl(PR_CAPBSET_DROP, CAP_SYS_NICE, 0, 0, 0); }

// The same for a command line run by the shell (util-linux's setpriv).
inline std::string without_realtime_priority(const std::string& command) {
  return "setpriv --bounding-set -sys_nice " + command;
}

// Before a test sends SIGHUP, SIGINT or SIGTERM to `syncplc run`, it waits
// until the run takes them itself (they are blocked and read with sigwait),
// or the default action kills it: a fixed sleep is not enough for a sanitizer
// build on a loaded machine. The run blocks them before it starts its HTTP
// server, whose address it then prints: started with `--http 127.0.0.1:0` (a
// free port, so the line is the same whatever other tests hold), the line
// kRunTakesSignals in its standard error says it is ready. (The signal masks
// in /proc cannot tell: ThreadSanitizer's own thread blocks every signal from
// the start, and a thread waiting in sigwait shows them unblocked.)
inline constexpr const char* kRunTakesSignals = "syncplc: HMI and HTTP API on http://127.0.0.1:";

// Waits up to `seconds` for `text` in the file `path`.
inline bool wait_for_text(const std::string& path, const std::string& text, int seconds = 60) {
  for (int i = 0; i < seconds * 50; ++i) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (ss.str().find(text) != std::string::npos) return true;
    usleep(20'000);
  }
  return false;
}

struct CliResult {
  int rc = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// `args` after the program name, shell-quoted by the caller where needed;
// standard input from `stdin_path`.
inline CliResult run_cli_from(const std::string& args, const std::string& stdin_path, bool realtime = true) {
  static int n = 0;
  std::string o = write_temp_file("cli" + std::to_string(++n) + ".out", "");
  std::string e = o + ".err";
  std::string cmd = std::string(SYNCPLC_BINARY) + " " + args + " >" + o + " 2>" + e + " <" + stdin_path;
  if (!realtime) cmd = without_realtime_priority(cmd);
  int status = std::system(cmd.c_str());
  CliResult r;
  r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(o);
  r.err = slurp(e);
  return r;
}

// Standard input empty (/dev/null: not a terminal).
inline CliResult run_cli(const std::string& args) { return run_cli_from(args, "/dev/null"); }

// A run whose scan never ends (see drop_realtime_priority).
inline CliResult run_cli_without_realtime(const std::string& args) { return run_cli_from(args, "/dev/null", false); }

// Standard input `input`, through a temporary file.
inline CliResult run_cli_input(const std::string& args, const std::string& input) {
  static int n = 0;
  return run_cli_from(args, write_temp_file("cli-stdin" + std::to_string(++n), input));
}

// A TCP port of 127.0.0.1 held by a listening socket for the object's life:
// a `run` given it finds it in use.
struct TakenPort {
  int fd = -1;
  int port = 0;
  TakenPort() {
    fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || listen(fd, 1) != 0) return;
    socklen_t len = sizeof a;
    getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~TakenPort() { release(); }
  void release() {
    if (fd >= 0) close(fd);
    fd = -1;
  }
  TakenPort(const TakenPort&) = delete;
  TakenPort& operator=(const TakenPort&) = delete;
};

}  // namespace syncplc::testing
