#include "runtime/core/task_cpus.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "runtime/core/program.hpp"

namespace syncplc {

TaskCpuChoice cpus_off_tasks(const cpu_set_t& process, const std::vector<int>& pinned) {
  TaskCpuChoice choice;
  choice.cpus = process;
  for (int cpu : pinned)
    if (cpu >= 0 && cpu < CPU_SETSIZE && CPU_ISSET(cpu, &choice.cpus)) {
      CPU_CLR(cpu, &choice.cpus);
      choice.off = true;
    }
  if (CPU_COUNT(&choice.cpus) == 0) {
    choice.cpus = process;
    choice.off = false;
  }
  return choice;
}

std::vector<int> pinned_cpus(const Program& program) {
  std::vector<int> cpus;
  for (const auto& task : program.tasks) {
    const int cpu = task->config().cpu;
    if (cpu >= 0 && std::find(cpus.begin(), cpus.end(), cpu) == cpus.end()) cpus.push_back(cpu);
  }
  std::sort(cpus.begin(), cpus.end());
  return cpus;
}

cpu_set_t process_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(getpid(), sizeof set, &set) != 0)
    for (int c = 0; c < CPU_SETSIZE; ++c) CPU_SET(c, &set);  // unknown: any (the kernel keeps to what exists)
  return set;
}

std::string keep_thread_to(pthread_t thread, const cpu_set_t& cpus) {
  if (const int rc = pthread_setaffinity_np(thread, sizeof cpus, &cpus); rc != 0) return std::strerror(rc);
  return {};
}

std::string cpu_list(const cpu_set_t& cpus) {
  std::string out;
  for (int c = 0; c < CPU_SETSIZE;) {
    if (!CPU_ISSET(c, &cpus)) {
      ++c;
      continue;
    }
    int last = c;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &cpus)) ++last;
    out += (out.empty() ? "" : ",") + std::to_string(c) + (last > c ? "-" + std::to_string(last) : "");
    c = last + 1;
  }
  return out;
}

}  // namespace syncplc
