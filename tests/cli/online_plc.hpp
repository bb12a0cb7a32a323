// The PLC the online commands' tests talk to, and everything about it that
// depends on which PLC that is. Today it is the HTTP API's test fixture
// (tests/hmi/fixture_server.mjs under node: canned, moving values, users
// viewer/operator/engineer with password NAME-pw). Once runtime/web is
// merged it becomes a `syncplc run` of a small project serving the API on a
// free port, with those users made by `syncplc user add`: only this file
// changes, the tests stay.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <optional>
#include <regex>
#include <string>
#include <thread>

#include "tests/support/cli_runner.hpp"

namespace syncplc::testing {

class OnlinePlc {
 public:
  // What the tests read, write and force, and the units they are shown with.
  static constexpr const char* kTag = "speed";  // LREAL, hmi: readwrite
  static constexpr const char* kTagUnit = "m/s";
  static constexpr const char* kElement = "pos[2]";  // an element of a read-only array
  static constexpr const char* kElementUnit = "rad";
  static constexpr const char* kPin = "ax1.x";  // a block pin
  static constexpr const char* kPinUnit = "rad";
  static constexpr const char* kTask = "servo";  // a task status lists
  // A project error the PLC's check finds (the fixture reports any NNxs).
  static constexpr const char* kBadPeriod = "10xs";

  static std::string password(const std::string& user) { return user + "-pw"; }

  // Why the tests cannot run here, or "" when they can.
  static std::string unavailable() {
    if (node().empty()) return "node is not installed (the API's test fixture runs on it)";
    return "";
  }

  OnlinePlc() {
    log_ = write_temp_file("online_plc.log", "");
    pid_ = fork();
    if (pid_ == 0) {
      if (!std::freopen(log_.c_str(), "w", stdout) || !std::freopen(log_.c_str(), "a", stderr)) _exit(126);
      const std::string fixture = std::string(SYNCPLC_SOURCE_DIR) + "/tests/hmi/fixture_server.mjs";
      const std::string n = node();
      execl(n.c_str(), n.c_str(), fixture.c_str(), "0", static_cast<char*>(nullptr));  // port 0: any free one
      _exit(127);
    }
    // It prints "fixture (test only) at http://127.0.0.1:PORT; ..." once it listens.
    static const std::regex at(R"(at (http://127\.0\.0\.1:\d+))");
    for (int i = 0; i < 200 && url_.empty(); ++i) {
      std::smatch m;
      const std::string log = slurp(log_);
      if (std::regex_search(log, m, at)) url_ = m[1];
      else std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~OnlinePlc() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  OnlinePlc(const OnlinePlc&) = delete;
  OnlinePlc& operator=(const OnlinePlc&) = delete;

  // "" when it did not start; log() says why.
  const std::string& url() const { return url_; }
  std::string log() const { return slurp(log_); }

 private:
  static std::string node() {
    FILE* p = popen("command -v node", "r");
    if (!p) return "";
    char buf[512] = {};
    const bool got = std::fgets(buf, sizeof buf, p) != nullptr;
    pclose(p);
    std::string s = got ? buf : "";
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    return s;
  }

  pid_t pid_ = -1;
  std::string log_, url_;
};

}  // namespace syncplc::testing
