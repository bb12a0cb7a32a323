// A project of two SIM_SERVO axes, master x and slave y, with the blocks of
// synchronized motion (MC_GearIn, MC_GearOut, MC_CamIn, MC_CamOut), run scan
// by scan by the virtual clock (tests/plcopen/test_mc_gear.cpp, test_mc_cam.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "tests/support/image_key.hpp"

namespace syncplc::sync_test {

constexpr double kT = 0.001;

// `blocks` and `connections` are appended to the two axes, their drives and
// MC_Power blocks (enabled); x: v_max 100, a_max 1000, d_max 1000; y as given.
inline std::string sync_project(const std::string& tags, const std::string& blocks, const std::string& connections,
                                const std::string& slave_limits = "v_max: 50, a_max: 500, d_max: 800") {
  return "tasks: [{name: motion, period: 1ms}]\ntags:\n  - {name: unused_tag, type: BOOL}\n" + tags +
         "blocks:\n"
         "  - {name: x, type: MC_AXIS, params: {v_max: 100, a_max: 1000, d_max: 1000}}\n"
         "  - {name: y, type: MC_AXIS, params: {" + slave_limits + "}}\n"
         "  - {name: dx, type: SIM_SERVO}\n"
         "  - {name: dy, type: SIM_SERVO}\n"
         "  - {name: px, type: MC_Power, params: {Axis: x}, inputs: {Enable: TRUE}}\n"
         "  - {name: py, type: MC_Power, params: {Axis: y}, inputs: {Enable: TRUE}}\n" +
         blocks +
         "connections:\n"
         "  - x.enable -> dx.enable\n  - x.drive_position -> dx.target\n  - x.reset -> dx.reset\n"
         "  - dx.position -> x.actual_position\n  - dx.power_on -> x.power_on\n"
         "  - dx.fault -> x.fault\n  - dx.fault_code -> x.fault_code\n"
         "  - y.enable -> dy.enable\n  - y.drive_position -> dy.target\n"
         "  - dy.position -> y.actual_position\n  - dy.power_on -> y.power_on\n" +
         connections;
}

class SyncRun {
 public:
  explicit SyncRun(const std::string& text) {
    auto r = load_project_text(text, "sync.yaml", LoadOptions{});
    for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
    prog_ = std::move(r.program);
    if (prog_) clock_ = std::make_unique<VirtualClock>(*prog_);
  }
  bool ok() const { return prog_ != nullptr; }
  Cell& cell(const std::string& ref) {
    auto r = prog_->resolve(ref);
    EXPECT_TRUE(r) << ref;
    return *prog_->live_cell(*r, testing::image_key());
  }
  bool b(const std::string& ref) { return cell(ref).get<bool>(); }
  double d(const std::string& ref) { return cell(ref).get<double>(); }
  int state(const std::string& axis) { return cell(axis + ".state").get<std::int16_t>(); }
  int error_id(const std::string& block) { return cell(block + ".ErrorID").get<std::uint16_t>(); }
  void set(const std::string& ref, bool v) { cell(ref).set<bool>(v); }
  void scan() { clock_->run_until(now_ += 1'000'000); }
  void scans(int n) {
    for (int i = 0; i < n; ++i) scan();
  }
  // Scans until `ref` is TRUE, at most `limit` scans; false if it never came.
  bool until(const std::string& ref, int limit) {
    for (int i = 0; i < limit; ++i) {
      scan();
      if (b(ref)) return true;
    }
    return false;
  }

 private:
  std::unique_ptr<Program> prog_;
  std::unique_ptr<VirtualClock> clock_;
  std::int64_t now_ = 0;
};

}  // namespace syncplc::sync_test
