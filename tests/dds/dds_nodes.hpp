// Two or more dds drivers in one test process, each with its own cells, as
// the scan would use them (tests/dds/test_dds_link.cpp, test_dds_inject.cpp).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "runtime/io/drivers.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc::ddstest {

class Setup final : public DriverSetup {
 public:
  std::int64_t task_period_ns() const override { return 1'000'000; }
  std::uint64_t seed() const override { return 1; }
  void error(const SourceLoc& where, const std::string& message) override { errors.push_back(where.text() + ": " + message); }
  std::vector<std::string> errors;
};

// This test process's own domain: tests of other processes run beside it.
inline int domain() { return 10 + static_cast<int>(getpid() % 200); }

struct Node {
  // startup_check 0 unless the body sets it: the nodes of a test start one
  // after the other, and the first would wait for its peer.
  explicit Node(const std::string& body, bool must_open = true) {
    Diagnostics d;
    const std::string check = body.find("startup_check") == std::string::npos ? "startup_check: 0s\n" : "";
    cfg = read_yaml_string("name: net\ntype: dds\ndomain: " + std::to_string(domain()) +
                               "\npeers: [127.0.0.1]\ninterface: 127.0.0.1\n" + check + body,
                           "node.yaml", d);
    drv = builtin_drivers().find("dds")->create(cfg, setup);
    EXPECT_TRUE(drv) << (setup.errors.empty() ? "" : setup.errors[0]);
    if (!drv) return;
    drv->set_name("net");
    for (const auto& c : drv->channels()) storage.emplace_back(c.length, Cell{});
    std::vector<Cell*> cells;
    for (auto& s : storage) cells.push_back(s.data());
    drv->bind(cells);
    opened = drv->open(&open_error);
    if (must_open) {
      EXPECT_TRUE(opened) << open_error;
    }
  }
  ~Node() {
    if (drv) drv->close();
  }
  int channel(const std::string& name) const {
    for (std::size_t i = 0; i < drv->channels().size(); ++i)
      if (drv->channels()[i].name == name) return static_cast<int>(i);
    ADD_FAILURE() << "no channel " << name;
    return 0;
  }
  Cell& at(const std::string& name, std::size_t i = 0) { return storage[static_cast<std::size_t>(channel(name))][i]; }
  // One scan of this node: latch, set the publication's values, write.
  void scan(std::uint64_t k, const std::string& pub = "", std::vector<double> values = {}) {
    ctx.scan = k;
    ctx.now_ns = static_cast<std::int64_t>(k) * 1'000'000;
    ctx.stop_request = nullptr;
    drv->latch_inputs(ctx);
    for (std::size_t i = 0; i < values.size(); ++i) at(pub, i).set<double>(values[i]);
    drv->write_outputs(ctx);
  }
  double counter(const std::string& name) const {
    for (const auto& [k, v] : drv->counters())
      if (k == name) return v;
    return -1;
  }
  Setup setup;
  bool opened = false;
  std::string open_error;
  ConfigNode cfg;
  std::unique_ptr<IoDriver> drv;
  std::vector<std::vector<Cell>> storage;
  ScanContext ctx;
};

// Latches `n` until `done` holds (a guard of 20 s against a hang, never a bound on speed).
template <class F>
bool latch_until(Node& n, F done) {
  const auto guard = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < guard) {
    n.drv->latch_inputs(n.ctx);
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return false;
}

inline std::string topic(const char* base) { return std::string(base) + "_" + std::to_string(getpid()); }

}  // namespace syncplc::ddstest
