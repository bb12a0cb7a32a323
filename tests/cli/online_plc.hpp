// The PLC the online commands' tests talk to: a real `syncplc run` of a small
// project (kProject below) with its HTTP API on a free port of 127.0.0.1
// (`--http 127.0.0.1:0`, the address taken from the line run prints), a
// database of its own, and the users viewer, operator and engineer (password
// NAME-pw) made beforehand by `syncplc user add`. Everything the tests need to
// know about that PLC is here; the tests stay the same whatever PLC it is.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

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
  // A project error the PLC's check finds: a period that is no duration.
  static constexpr const char* kBadPeriod = "10xs";

  // The project: `servo` runs a PD controller on a position; `slow` burns
  // 15 ms in its first scan only (its period is 10 ms), so the event log
  // holds exactly one `overrun` whatever the machine's load, and no core is
  // kept busy afterwards.
  static constexpr const char* kProject = R"(project: {name: online_cli, version: 1.0.0}
tasks:
  - {name: servo, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: speed, type: LREAL, unit: m/s, hmi: readwrite}
  - {name: pos, type: "ARRAY[1..3] OF LREAL", unit: rad, hmi: read, init: [0.5, 1.25, 2.0]}
blocks:
  - {name: ax1, type: PD_CONTROLLER, task: servo, inputs: {x_d: 1.0}}
  - {name: first_done, type: UNIT_DELAY, datatype: BOOL, task: slow, inputs: {IN: TRUE}}
  - {name: burn_time, type: SEL, datatype: TIME, task: slow, inputs: {IN0: 15ms, IN1: 0ms}}
  - {name: burn, type: BURN, task: slow}
connections:
  - pos[1] -> ax1.x
  - first_done.OUT -> burn_time.G
  - burn_time.OUT -> burn.EXEC
)";

  static std::string password(const std::string& user) { return user + "-pw"; }

  // `extra`: more arguments of run, e.g. --http-cert and --http-key (then
  // `scheme` is "https").
  explicit OnlinePlc(std::vector<std::string> extra = {}, const std::string& scheme = "http") {
    static int n = 0;
    dir_ = std::filesystem::path(write_temp_file("online_plc.marker", "")).parent_path() /
           ("online_plc_" + std::to_string(getpid()) + "_" + std::to_string(++n));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    project_ = (dir_ / "online.yaml").string();
    write_file(project_, kProject);
    db_ = (dir_ / "plc.db").string();
    for (const char* user : {"viewer", "operator", "engineer"}) {
      const CliResult r = run_cli_input(std::string("user add ") + user + " --role " + user + " --password-stdin --db " + db_,
                                        password(user) + "\n");
      if (r.rc != 0) {
        setup_error_ = "syncplc user add " + std::string(user) + " failed (" + std::to_string(r.rc) + "): " + r.err;
        return;
      }
    }
    log_ = (dir_ / "run.log").string();
    pid_ = fork();
    if (pid_ == 0) {
      if (!std::freopen(log_.c_str(), "w", stdout) || !std::freopen(log_.c_str(), "a", stderr)) _exit(126);
      std::vector<std::string> args = {SYNCPLC_BINARY, "run", project_, "--no-status", "--db", db_,
                                       "--modbus-port", "0", "--http", "127.0.0.1:0"};
      args.insert(args.end(), extra.begin(), extra.end());
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      execv(SYNCPLC_BINARY, argv.data());
      _exit(127);
    }
    // "syncplc: HMI and HTTP API on SCHEME://127.0.0.1:PORT/" once it serves
    // (a generous wait: only a hang ends it).
    const std::string line = "HTTP API on " + scheme + "://127.0.0.1:";
    if (!wait_for_text(log_, line, 120)) return;
    std::smatch m;
    const std::string text = slurp(log_);
    const std::regex at("HTTP API on (" + scheme + R"(://127\.0\.0\.1:\d+)/)");
    if (std::regex_search(text, m, at)) url_ = m[1];
  }
  ~OnlinePlc() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
    std::error_code ec;
    if (!HasFailure()) std::filesystem::remove_all(dir_, ec);
  }
  OnlinePlc(const OnlinePlc&) = delete;
  OnlinePlc& operator=(const OnlinePlc&) = delete;

  // "" when it did not start; log() says why.
  const std::string& url() const { return url_; }
  std::string log() const { return setup_error_ + slurp(log_); }
  const std::string& project() const { return project_; }

 private:
  static bool HasFailure() { return ::testing::Test::HasFailure(); }
  static void write_file(const std::string& path, const std::string& text) {
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return;
    std::fputs(text.c_str(), f);
    std::fclose(f);
  }

  pid_t pid_ = -1;
  std::filesystem::path dir_;
  std::string project_, db_, log_, url_, setup_error_;
};

}  // namespace syncplc::testing
