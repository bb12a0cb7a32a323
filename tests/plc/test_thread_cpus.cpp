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
#include <set>
#include <memory>
#include <string>
#include <vector>

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

// The control thread moves the others first, then names itself (plc.cpp);
// each other thread names itself when it starts, which may come after that
// (the supervisor's did, once in a sanitizer run): wait for every name.
bool every_thread_named() {
  std::set<std::string> seen;
  for (const auto& [thread, list] : thread_cpus()) seen.insert(thread.substr(0, thread.find('/')));
  return seen.size() == 5;  // http-net, http-work, store, supervisor, plc-control
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

// A PLC running kPinned with its HTTP server and a store (`db` beside the
// project), the HTTP threads on `http_cpus` when given; the CPU lists the
// tests expect: every CPU of the process, and all but CPU 1.
struct PinnedRun {
  std::string everything, off_task, pinned, free;
  std::unique_ptr<Plc> plc;
  std::string why;

  PinnedRun(const std::string& db, std::vector<int> http_cpus = {}) {
    const cpu_set_t process = process_cpus();
    cpu_set_t others = process;
    CPU_CLR(1, &others);
    everything = cpu_list(process);
    off_task = cpu_list(others);
    pinned = write_project("pinned_cpu.yaml", kPinned);
    free = write_project("free_cpu.yaml", kFree);
    PlcOptions o = options(pinned);
    o.db = (std::filesystem::path(pinned).parent_path() / db).string();  // a store thread
    std::filesystem::remove(o.db);
    o.http.enabled = true;
    o.http.port = 0;
    o.http.cpus = std::move(http_cpus);
    std::vector<std::string> notices;
    PlcFailure failure;
    plc = Plc::open(o, notices, &failure);
    why = failure.why;
    if (plc) plc->start();
  }
  ~PinnedRun() {
    if (plc) plc->stop("end of test");
  }
  ChangeResult change_to(const std::string& path) {
    ChangeRequest c;
    c.path = path;
    return plc->change(c);
  }
};

bool has_cpus_0_and_1() {
  const cpu_set_t process = process_cpus();
  return CPU_ISSET(0, &process) && CPU_ISSET(1, &process);
}

TEST(PlcThreadCpus, ThreadsThatAreNotRealTimeKeepOffAPinnedTasksCpuAndFollowOnlineChanges) {
  if (!has_cpus_0_and_1()) GTEST_SKIP() << "needs CPUs 0 and 1";
  PinnedRun run("thread_cpus.db");
  ASSERT_TRUE(run.plc) << run.why;
  ASSERT_TRUE(eventually(every_thread_named));
  EXPECT_TRUE(all_on(run.off_task)) << "task main is pinned to CPU 1";
  const ChangeResult r1 = run.change_to(run.free);
  ASSERT_TRUE(r1.accepted) << r1.summary;
  EXPECT_TRUE(all_on(run.everything)) << "after an online change that unpins task main";
  const ChangeResult r2 = run.change_to(run.pinned);
  ASSERT_TRUE(r2.accepted) << r2.summary;
  EXPECT_TRUE(all_on(run.off_task)) << "after an online change that pins task main again";
}

// --http-cpus: the HTTP server's threads where the setting says, even on a
// pinned task's CPU, through online changes; the others follow the rule.
TEST(PlcThreadCpus, HttpCpusKeepTheHttpServersThreadsWhereTheSettingSays) {
  if (!has_cpus_0_and_1()) GTEST_SKIP() << "needs CPUs 0 and 1";
  PinnedRun run("http_cpus.db", {1});
  ASSERT_TRUE(run.plc) << run.why;
  ASSERT_TRUE(eventually(every_thread_named));
  EXPECT_TRUE(all_on(run.off_task, "1"));
  const ChangeResult r = run.change_to(run.free);
  ASSERT_TRUE(r.accepted) << r.summary;
  EXPECT_TRUE(all_on(run.everything, "1"));
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
