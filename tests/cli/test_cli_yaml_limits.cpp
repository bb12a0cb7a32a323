// A project file of nested YAML aliases ("billion laughs": 600 bytes that
// expand to 10^8 nodes) is refused with its place on every path of the
// command line, in bounded memory: `check`, `run`, and an online change by
// SIGHUP and by `syncplc reload`, after which the PLC runs on. Each `syncplc`
// runs with its address space capped (tests/support/bounded_child.hpp), so
// that a loader that expands the aliases fails here, not the machine.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/yaml_laughs.hpp"
#include "tests/support/bounded_child.hpp"
#include "tests/support/cli_runner.hpp"
#include "tests/support/test_blocks.hpp"

// Named, not anonymous: unity builds put several test files in one
// translation unit (SYNCPLC_UNITY), where their helpers must not meet.
namespace cli_yaml_limits_test {

using syncplc::testing::slurp;
using syncplc::testing::write_temp_file;

using syncplc::testing::laughs;  // tests/support/yaml_laughs.hpp: refused at line 5, column 45
const char* kRefused = ":5:45: alias *l2 expands the file past its limit of 10000 YAML nodes";

// The most a refused load may take, whole process beyond what it inherited
// from the test when it was forked: a plain `check` peaks at about 10 MB
// (several times that under a sanitizer); the expansion would take gigabytes.
constexpr long kBoundKb = 200 * 1024;
// What a refused online change may add to a running PLC's peak. Under
// ThreadSanitizer the first load on the PLC's control thread maps that
// thread's allocator caches and their shadow (about 60 MB seen): still far
// from the gigabytes of an expansion.
#if defined(__SANITIZE_THREAD__)
constexpr long kReloadBoundKb = 200 * 1024;
#else
constexpr long kReloadBoundKb = 50 * 1024;
#endif

// Forks and execs `syncplc args...` under the cap, stdout and stderr to files.
pid_t start(const std::vector<std::string>& args, const std::string& out) {
  pid_t pid = fork();
  if (pid == 0) {
    syncplc::testing::cap_address_space();
    FILE* f1 = std::freopen(out.c_str(), "w", stdout);
    FILE* f2 = std::freopen((out + ".err").c_str(), "w", stderr);
    (void)f1;
    (void)f2;
    std::vector<char*> argv{const_cast<char*>(SYNCPLC_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(SYNCPLC_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

// The peak resident memory of a running process (VmHWM), in kB.
long vm_hwm_kb(pid_t pid) {
  std::ifstream s("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(s, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
  return -1;
}

TEST(CliYamlLimits, CheckRefusesNestedAliasesWithTheirPlace) {
  const std::string path = write_temp_file("laughs_check.yaml", laughs());
  const std::string out = path + ".out";
  const long inherited = syncplc::testing::rss_kb();
  auto end = syncplc::testing::wait_child(start({"check", path}, out), inherited);
  ASSERT_TRUE(end.exited) << "ended by signal " << end.status << "\n" << slurp(out + ".err");
  EXPECT_EQ(end.status, 2) << slurp(out + ".err");
  EXPECT_NE(slurp(out + ".err").find(path + kRefused), std::string::npos) << slurp(out + ".err");
  EXPECT_LT(end.grown_kb(), kBoundKb);
}

TEST(CliYamlLimits, RunRefusesToStart) {
  const std::string path = write_temp_file("laughs_run.yaml", laughs());
  const std::string out = path + ".out";
  const long inherited = syncplc::testing::rss_kb();
  auto end = syncplc::testing::wait_child(
      start({"run", path, "--duration", "1s", "--no-status", "--modbus-port", "0", "--http", "off"}, out), inherited);
  ASSERT_TRUE(end.exited) << "ended by signal " << end.status << "\n" << slurp(out + ".err");
  EXPECT_EQ(end.status, 2) << slurp(out + ".err");
  EXPECT_NE(slurp(out + ".err").find(path + kRefused), std::string::npos) << slurp(out + ".err");
  EXPECT_LT(end.grown_kb(), kBoundKb);
}

// A running PLC whose file becomes a billion laughs: SIGHUP and `syncplc
// reload` are both refused with the place, the PLC runs on, and its peak
// memory stays small (a PLC locked in memory by mlockall would otherwise be
// ended by the kernel).
TEST(CliYamlLimits, OnlineChangesBySighupAndReloadAreRefusedAndThePlcRunsOn) {
  const std::string good = "tasks: [{name: main, period: 1ms}]\n"
                           "tags: [{name: level, type: LREAL, init: 3.5}, {name: out, type: LREAL}]\n"
                           "blocks: [{name: m, type: MOVE}]\nconnections: [level -> m.IN, m.OUT -> out]\n";
  const std::string path = write_temp_file("laughs_reload.yaml", good);
  const std::string out = path + ".out", err = out + ".err";
  const std::string pid_file = path + ".pid";
  pid_t pid = start({"run", path, "--no-status", "--modbus-port", "0", "--http", "127.0.0.1:0", "--pid-file", pid_file}, out);
  ASSERT_TRUE(syncplc::testing::wait_for_text(err, syncplc::testing::kRunTakesSignals)) << slurp(err);
  const long hwm_running = vm_hwm_kb(pid);  // the PLC's own peak so far (a sanitizer's shadow included)

  write_temp_file("laughs_reload.yaml", laughs());
  kill(pid, SIGHUP);
  EXPECT_TRUE(syncplc::testing::wait_for_text(err, "rejected (1 error); the running program continues unchanged")) << slurp(err);
  EXPECT_NE(slurp(err).find(path + kRefused), std::string::npos) << slurp(err);
  EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "the PLC ended";

  // `syncplc reload` asks the same instance (SIGUSR1 and its answer file).
  auto r = syncplc::testing::run_cli("reload --pid-file " + pid_file);
  EXPECT_EQ(r.rc, 1) << r.out << r.err;
  EXPECT_NE(r.out.find(path + kRefused), std::string::npos) << r.out << r.err;
  EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "the PLC ended";
  // The two refused loads took next to nothing beyond what the PLC had.
  const long hwm = vm_hwm_kb(pid);
  EXPECT_GT(hwm_running, 0);
  EXPECT_LT(hwm - hwm_running, kReloadBoundKb) << hwm_running << " kB before, " << hwm << " kB after";

  kill(pid, SIGTERM);
  auto end = syncplc::testing::wait_child(pid);
  ASSERT_TRUE(end.exited) << "ended by signal " << end.status << "\n" << slurp(err);
  EXPECT_EQ(end.status, 0) << slurp(err);
  EXPECT_NE(slurp(out).find("Stopped by SIGTERM"), std::string::npos) << slurp(out);
}

}  // namespace
