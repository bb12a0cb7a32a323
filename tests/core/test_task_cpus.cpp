// The rule for the threads that are not real-time (runtime/core/task_cpus):
// the process's CPUs minus the pinned tasks' CPUs, unless none is left.
#include <gtest/gtest.h>

#include <initializer_list>

#include "runtime/core/task_cpus.hpp"

namespace syncplc {
namespace {

cpu_set_t set_of(std::initializer_list<int> cpus) {
  cpu_set_t s;
  CPU_ZERO(&s);
  for (int c : cpus) CPU_SET(c, &s);
  return s;
}

TEST(TaskCpus, PinnedCpusAreTakenOutOfTheProcessSet) {
  const TaskCpuChoice c = cpus_off_tasks(set_of({0, 1, 2, 3}), {1, 3});
  EXPECT_TRUE(c.off);
  EXPECT_EQ(cpu_list(c.cpus), "0,2");
}

TEST(TaskCpus, NothingPinnedLeavesTheProcessSet) {
  const TaskCpuChoice c = cpus_off_tasks(set_of({0, 1}), {});
  EXPECT_FALSE(c.off);
  EXPECT_EQ(cpu_list(c.cpus), "0-1");
}

TEST(TaskCpus, WhenNoCpuIsLeftTheProcessSetStaysUnchanged) {
  // Two CPUs, a task on each: the threads must run somewhere.
  const TaskCpuChoice both = cpus_off_tasks(set_of({0, 1}), {0, 1});
  EXPECT_FALSE(both.off);
  EXPECT_EQ(cpu_list(both.cpus), "0-1");
  // A process kept to CPU 2 (taskset) with its task pinned there.
  const TaskCpuChoice one = cpus_off_tasks(set_of({2}), {2});
  EXPECT_FALSE(one.off);
  EXPECT_EQ(cpu_list(one.cpus), "2");
}

TEST(TaskCpus, PinnedCpusOutsideTheProcessSetAreIgnored) {
  const TaskCpuChoice c = cpus_off_tasks(set_of({0, 1}), {5, -1, 4096});
  EXPECT_FALSE(c.off);
  EXPECT_EQ(cpu_list(c.cpus), "0-1");
}

TEST(TaskCpus, ListsAsProcWritesThem) {
  EXPECT_EQ(cpu_list(set_of({0, 2, 3, 4, 7})), "0,2-4,7");
  EXPECT_EQ(cpu_list(set_of({})), "");
}

}  // namespace
}  // namespace syncplc
