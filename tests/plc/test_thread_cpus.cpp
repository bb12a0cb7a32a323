// The PLC's threads that are not real-time (the HTTP server's network and
// worker threads, the store, the supervisor, the control thread) keep off
// the CPU a task is pinned to (runtime/core/task_cpus.hpp), and follow an
// online change that unpins or pins it. Read from /proc, by thread name, as
// `ps -L` and `top -H` show them.
#include <gtest/gtest.h>
#include <sched.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "runtime/core/task_cpus.hpp"
#include "runtime/plc/plc.hpp"
#include "tests/plc/plc_test_util.hpp"

namespace syncplc::plc {
namespace {

using testing::eventually;
using testing::options;
using testing::write_project;

const char* kPinned = R"(
tasks: [{name: main, period: 2ms, cpu: 1}]
tags: [{name: total, type: LREAL}]
blocks: [{name: acc, type: ACC, task: main, inputs: {IN: 1.0}}]
connections: [acc.SUM -> total]
)";

const char* kFree = R"(
tasks: [{name: main, period: 2ms}]
tags: [{name: total, type: LREAL}]
blocks: [{name: acc, type: ACC, task: main, inputs: {IN: 1.0}}]
connections: [acc.SUM -> total]
)";

// The threads of this process that must keep off a pinned task's CPU: each one's Cpus_allowed_list, by "name/tid".
std::map<std::string, std::string> thread_cpus() {
  std::map<std::string, std::string> out;
  for (const auto& t : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string name;
    std::getline(std::ifstream(t.path() / "comm"), name);
    if (name != "http-net" && name != "http-work" && name != "store" && name != "supervisor" && name != "plc-control")
      continue;
    std::ifstream status(t.path() / "status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("Cpus_allowed_list:", 0) == 0)
        out[name + "/" + t.path().filename().string()] = line.substr(line.find_first_not_of(" \t", 18));
  }
  return out;
}

// The control thread moves the others first, then names itself (plc.cpp).
bool control_thread_named() {
  for (const auto& [thread, list] : thread_cpus())
    if (thread.rfind("plc-control/", 0) == 0) return true;
  return false;
}

// Every one of them on `cpus` (the HTTP server's on `http_cpus` when given),
// and the HTTP server's threads, the store, the supervisor and the control thread all there.
::testing::AssertionResult all_on(const std::string& cpus, const std::string& http_cpus = "") {
  const auto threads = thread_cpus();
  std::string wrong;
  std::map<std::string, int> seen;
  for (const auto& [thread, list] : threads) {
    ++seen[thread.substr(0, thread.find('/'))];
    const bool http = thread.rfind("http-", 0) == 0;
    if (list != (http && !http_cpus.empty() ? http_cpus : cpus)) wrong += " " + thread + " on " + list;
  }
  for (const char* name : {"http-net", "http-work", "store", "supervisor", "plc-control"})
    if (!seen.count(name)) wrong += std::string(" no ") + name + " thread";
  if (wrong.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "expected every thread on CPU " << cpus << ":" << wrong;
}

TEST(PlcThreadCpus, ThreadsThatAreNotRealTimeKeepOffAPinnedTasksCpuAndFollowOnlineChanges) {
  const cpu_set_t process = process_cpus();
  if (!CPU_ISSET(0, &process) || !CPU_ISSET(1, &process)) GTEST_SKIP() << "needs CPUs 0 and 1";
  cpu_set_t others = process;
  CPU_CLR(1, &others);
  const std::string everything = cpu_list(process), off_task = cpu_list(others);

  const std::string pinned = write_project("pinned_cpu.yaml", kPinned);
  const std::string free = write_project("free_cpu.yaml", kFree);
  PlcOptions o = options(pinned);
  o.db = (std::filesystem::path(pinned).parent_path() / "thread_cpus.db").string();  // a store thread
  std::filesystem::remove(o.db);
  o.http.enabled = true;
  o.http.port = 0;
  std::vector<std::string> notices;
  PlcFailure failure;
  auto plc = Plc::open(o, notices, &failure);
  ASSERT_TRUE(plc) << failure.why;
  plc->start();
  ASSERT_TRUE(eventually(control_thread_named));
  EXPECT_TRUE(all_on(off_task)) << "task main is pinned to CPU 1";

  ChangeRequest unpin;
  unpin.path = free;
  const ChangeResult r1 = plc->change(unpin);
  ASSERT_TRUE(r1.accepted) << r1.summary;
  EXPECT_TRUE(all_on(everything)) << "after an online change that unpins task main";

  ChangeRequest pin;
  pin.path = pinned;
  const ChangeResult r2 = plc->change(pin);
  ASSERT_TRUE(r2.accepted) << r2.summary;
  EXPECT_TRUE(all_on(off_task)) << "after an online change that pins task main again";
  plc->stop("end of test");
}

// --http-cpus: the HTTP server's threads where the setting says, even on a
// pinned task's CPU, through online changes; the others follow the rule.
TEST(PlcThreadCpus, HttpCpusKeepTheHttpServersThreadsWhereTheSettingSays) {
  const cpu_set_t process = process_cpus();
  if (!CPU_ISSET(0, &process) || !CPU_ISSET(1, &process)) GTEST_SKIP() << "needs CPUs 0 and 1";
  cpu_set_t others = process;
  CPU_CLR(1, &others);
  const std::string everything = cpu_list(process), off_task = cpu_list(others);
  const std::string pinned = write_project("pinned_cpu.yaml", kPinned);
  const std::string free = write_project("free_cpu.yaml", kFree);
  PlcOptions o = options(pinned);
  o.db = (std::filesystem::path(pinned).parent_path() / "http_cpus.db").string();
  std::filesystem::remove(o.db);
  o.http.enabled = true;
  o.http.port = 0;
  o.http.cpus = {1};
  std::vector<std::string> notices;
  PlcFailure failure;
  auto plc = Plc::open(o, notices, &failure);
  ASSERT_TRUE(plc) << failure.why;
  plc->start();
  ASSERT_TRUE(eventually(control_thread_named));
  EXPECT_TRUE(all_on(off_task, "1"));
  ChangeRequest unpin;
  unpin.path = free;
  const ChangeResult r = plc->change(unpin);
  ASSERT_TRUE(r.accepted) << r.summary;
  EXPECT_TRUE(all_on(everything, "1"));
  plc->stop("end of test");
}

TEST(PlcThreadCpus, HttpCpusTheProcessMayNotUseStopTheStart) {
  const std::string pinned = write_project("pinned_cpu.yaml", kPinned);
  PlcOptions o = options(pinned);
  o.http.enabled = true;
  o.http.port = 0;
  o.http.cpus = {1023};
  std::vector<std::string> notices;
  PlcFailure failure;
  auto plc = Plc::open(o, notices, &failure);
  ASSERT_FALSE(plc);
  EXPECT_EQ(failure.why, "--http-cpus: CPU 1023 is not one this process may use (" + cpu_list(process_cpus()) + ")");
}

}  // namespace
}  // namespace syncplc::plc
