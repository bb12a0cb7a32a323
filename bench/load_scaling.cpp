// How project loading scales (issues 11 and 21): a generated project with one
// task and a chain of N ADD blocks (b0.OUT -> b1.IN1, b1.OUT -> b2.IN1, ...,
// every IN2 a constant, the last OUT into a tag), loaded with load_project as
// `syncplc check` does. The chain is written in three shapes:
//
//   compact    one line per block, no more than needed:
//                - {name: b1, type: ADD, inputs: {IN2: 1}}
//   typed      one line per block as docs/project-format.md writes them
//              (the shape users write: task, datatype, inputs):
//                - {name: b1, type: ADD, task: main, datatype: LREAL, inputs: {IN2: 1.0}}
//   multiline  a line per key, with a description, as the docs' first
//              blocks example:
//                - name: b1
//                  type: ADD ...
//
// Each N and shape is loaded in a child process of its own, so that its
// peak resident memory (VmHWM) is its own.
//
//   build/bench/bench_load_scaling [--no-fork] [--shape compact|typed|multiline] [N ...]
//   (default: every shape, N = 10000 50000 100000)
//
// --no-fork loads in this process (for heaptrack or perf, which follow one
// process); peak RSS is then the largest so far.
//
// Prints one line per N and shape: file size, load time (wall clock and CPU
// time of one load) and the child's peak RSS. Plain program, no Google
// Benchmark: one load of 100,000 blocks is the measurement.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "runtime/project/loader.hpp"

namespace {

// Writes the chain project to `path` in `shape`; returns its size in bytes.
std::size_t write_chain(const std::string& path, long n, const std::string& shape) {
  std::ofstream f(path);
  f << "project: {name: chain}\n"
       "tasks:\n  - {name: main, period: 10ms}\n"
       "tags:\n  - {name: total, type: LREAL}\n"
       "blocks:\n";
  for (long i = 0; i < n; ++i) {
    if (shape == "compact") {
      f << "  - {name: b" << i << ", type: ADD, inputs: {IN2: 1";
      if (i == 0) f << ", IN1: 0";
      f << "}}\n";
    } else if (shape == "typed") {
      f << "  - {name: b" << i << ", type: ADD, task: main, datatype: LREAL, inputs: {";
      if (i == 0) f << "IN1: 0.0, ";
      f << "IN2: 1.0}}\n";
    } else {
      f << "  - name: b" << i << "\n    type: ADD\n    task: main\n    datatype: LREAL\n    inputs:\n";
      if (i == 0) f << "      IN1: 0.0\n";
      f << "      IN2: 1.0\n    description: step " << i << " of the chain\n";
    }
  }
  f << "connections:\n";
  for (long i = 1; i < n; ++i) f << "  - b" << i - 1 << ".OUT -> b" << i << ".IN1\n";
  f << "  - b" << n - 1 << ".OUT -> total\n";
  f.flush();
  return static_cast<std::size_t>(f.tellp());
}

// Peak resident set of this process in kB, from /proc/self/status.
long peak_rss_kb() {
  std::ifstream s("/proc/self/status");
  std::string line;
  while (std::getline(s, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
  return -1;
}

// User + system CPU time of this process in seconds: on a machine shared with
// other work, the wall time also counts the time others had the CPU.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto sec = [](const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6; };
  return sec(u.ru_utime) + sec(u.ru_stime);
}

int load_one(const std::string& path, const std::string& shape, long n, std::size_t bytes) {
  long before = peak_rss_kb();
  double c0 = cpu_seconds();
  auto t0 = std::chrono::steady_clock::now();
  auto r = syncplc::load_project(path);
  auto t1 = std::chrono::steady_clock::now();
  double cpu = cpu_seconds() - c0;
  if (!r.ok()) {
    for (const auto& d : r.diagnostics.sorted()) std::fprintf(stderr, "%s\n", d.text().c_str());
    return 1;
  }
  double s = std::chrono::duration<double>(t1 - t0).count();
  std::printf("%-9s %9ld blocks  %6.2f MB file  %7.3f s wall  %7.3f s CPU  peak RSS %7.1f MB (%.1f MB before loading)\n",
              shape.c_str(), n, static_cast<double>(bytes) / 1e6, s, cpu, static_cast<double>(peak_rss_kb()) / 1024.0,
              static_cast<double>(before) / 1024.0);
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<long> sizes;
  std::vector<std::string> shapes;
  bool fork_each = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--no-fork") fork_each = false;
    else if (a == "--shape" && i + 1 < argc) shapes.push_back(argv[++i]);
    else sizes.push_back(std::atol(argv[i]));
  }
  if (sizes.empty()) sizes = {10'000, 50'000, 100'000};
  if (shapes.empty()) shapes = {"compact", "typed", "multiline"};
  for (const auto& shape : shapes)
    if (shape != "compact" && shape != "typed" && shape != "multiline") {
      std::fprintf(stderr, "--shape: compact, typed or multiline\n");
      return 2;
    }
  int status_all = 0;
  for (long n : sizes) {
    if (n < 1) {
      std::fprintf(stderr, "N must be at least 1\n");
      return 2;
    }
    for (const auto& shape : shapes) {
      std::string path = "/tmp/syncplc_chain_" + std::to_string(getpid()) + "_" + shape + "_" + std::to_string(n) + ".yaml";
      std::size_t bytes = write_chain(path, n, shape);
      if (!fork_each) {
        if (load_one(path, shape, n, bytes) != 0) status_all = 1;
        std::remove(path.c_str());
        continue;
      }
      pid_t pid = fork();
      if (pid == 0) _exit(load_one(path, shape, n, bytes));
      int status = 0;
      waitpid(pid, &status, 0);
      std::remove(path.c_str());
      if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) status_all = 1;
    }
  }
  return status_all;
}
