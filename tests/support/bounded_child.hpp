// Runs a piece of a test in a child process with a cap on its address space,
// and reports how it ended and its peak resident memory: a test of "this
// input is refused in bounded memory" that fails on a loader that expands the
// input fails by the child running out of its cap, not by the machine
// running out of memory.
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>

namespace syncplc::testing {

// AddressSanitizer and ThreadSanitizer reserve terabytes of address space for
// their shadow memory: under them no cap is set (the peak RSS is still checked).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

// The cap: far above what the refused inputs of these tests cost once
// refused, far below what their expansion takes (tens of gigabytes).
inline constexpr rlim_t kAddressSpaceCap = rlim_t{2} << 30;

// Sets the cap in this process (a child about to run the code or exec a program).
inline void cap_address_space() {
  if (kSanitized) return;
  rlimit r{kAddressSpaceCap, kAddressSpaceCap};
  setrlimit(RLIMIT_AS, &r);
}

// This process's resident memory now (VmRSS), in kB.
inline long rss_kb() {
  std::ifstream s("/proc/self/status");
  std::string line;
  while (std::getline(s, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  return 0;
}

struct ChildEnd {
  bool exited = false;    // by exit (else by a signal, e.g. SIGABRT after std::bad_alloc)
  int status = -1;        // exit status, or the signal
  long maxrss_kb = 0;     // the child's peak resident memory (getrusage's ru_maxrss)
  long inherited_kb = 0;  // the parent's resident memory when it forked
  // What the child took beyond what it inherited: a forked child starts with
  // its parent's pages, and the peak of a program it execs counts them too
  // (a test program that has run many tests, under a sanitizer, holds
  // hundreds of MB).
  long grown_kb() const { return maxrss_kb - inherited_kb; }
};

// Waits for `pid` and takes its resource usage; `inherited_kb`: rss_kb()
// taken just before the fork.
inline ChildEnd wait_child(pid_t pid, long inherited_kb = 0) {
  ChildEnd e;
  e.inherited_kb = inherited_kb;
  int st = 0;
  rusage ru{};
  if (wait4(pid, &st, 0, &ru) != pid) return e;
  e.exited = WIFEXITED(st);
  e.status = e.exited ? WEXITSTATUS(st) : WTERMSIG(st);
  e.maxrss_kb = ru.ru_maxrss;
  return e;
}

// Runs `body` in a forked child under the cap; its return value is the exit status.
inline ChildEnd run_bounded(const std::function<int()>& body) {
  const long inherited = rss_kb();
  pid_t pid = fork();
  if (pid == 0) {
    cap_address_space();
    int rc = 1;
    try {
      rc = body();
    } catch (...) {
      rc = 99;  // e.g. std::bad_alloc at the cap
    }
    std::_Exit(rc);  // no atexit handlers of the test program in the child
  }
  if (pid < 0) return {};
  return wait_child(pid, inherited);
}

}  // namespace syncplc::testing
