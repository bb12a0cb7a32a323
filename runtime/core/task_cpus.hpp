// Where the PLC's threads that are not real-time run: off the CPUs the
// project pins its tasks to (task `cpu:`). Their system calls, TCP
// processing and cache traffic would otherwise land where a task must wake
// on time (docs/benchmarks.md sections 5 and 16). One rule for the Modbus
// server, the HTTP server's threads, the store, the supervisor and the
// control thread.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <string>
#include <vector>

namespace syncplc {

class Program;

struct TaskCpuChoice {
  cpu_set_t cpus;    // where the thread may run
  bool off = false;  // true: some CPU was left out for a pinned task
};

// The CPUs `process` allows minus `pinned`, unless that leaves none: then
// `process` unchanged (a thread must run somewhere; on one CPU, the tasks'
// priority is what keeps them on time). Pinned CPUs outside `process` are
// ignored.
TaskCpuChoice cpus_off_tasks(const cpu_set_t& process, const std::vector<int>& pinned);

// The CPUs `program`'s tasks are pinned to (each once, in order).
std::vector<int> pinned_cpus(const Program& program);

// The CPUs the process may use (the main thread's set, as `taskset` or
// systemd's CPUAffinity= gave it).
cpu_set_t process_cpus();

// Moves `thread` to `cpus`; "" or why it could not.
std::string keep_thread_to(pthread_t thread, const cpu_set_t& cpus);

// "1", "0,2-3": a set as /proc's Cpus_allowed_list writes it.
std::string cpu_list(const cpu_set_t& cpus);

}  // namespace syncplc
