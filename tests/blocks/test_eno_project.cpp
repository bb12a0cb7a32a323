// ENO in a project: connectable like any output, and the task applies the
// finite-input rule (the tags hold the last valid output, one event per
// series of faulting scans).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tests/support/image_key.hpp"
#include "fblocks/library.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc {
namespace {

std::unique_ptr<Program> load(const std::string& yaml) {
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(yaml, "eno.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return std::move(r.program);
}

Cell& tag(Program& p, const std::string& name) { return *p.live_cell(*p.resolve(name), ::syncplc::testing::image_key()); }

TEST(EnoProject, PidHoldsItsOutputAndReportsThroughEno) {
  auto p = load(R"(
tasks:
  - {name: loop, period: 1ms}
tags:
  - {name: pv, type: LREAL, hmi: readwrite}
  - {name: y, type: LREAL}
  - {name: ok, type: BOOL}
  - {name: alarm, type: BOOL}
blocks:
  - {name: pid, type: PID, task: loop, params: {Kp: 2}, inputs: {setpoint: 1.0}}
  - {name: inv, type: NOT, task: loop}
connections:
  - pv -> pid.actual
  - pid.y -> y
  - pid.ENO -> ok
  - pid.ENO -> inv.IN
  - inv.OUT -> alarm
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  tag(*p, "pv").set<double>(0.5);
  clock.run_until(3'000'000);
  EXPECT_DOUBLE_EQ(tag(*p, "y").get<double>(), 1.0);
  EXPECT_TRUE(tag(*p, "ok").get<bool>());
  EXPECT_FALSE(tag(*p, "alarm").get<bool>());
  tag(*p, "pv").set<double>(std::numeric_limits<double>::quiet_NaN());
  clock.run_until(8'000'000);
  EXPECT_DOUBLE_EQ(tag(*p, "y").get<double>(), 1.0);  // the tag holds the last valid output
  EXPECT_FALSE(tag(*p, "ok").get<bool>());
  EXPECT_TRUE(tag(*p, "alarm").get<bool>());
  int faults = 0;
  Event e;
  while (p->tasks[0]->pop_event(e))
    if (e.kind == EventKind::BlockFault) {
      ++faults;
      EXPECT_STREQ(e.message, "input not finite");
      EXPECT_TRUE(std::isnan(e.value));
    }
  EXPECT_EQ(faults, 1);  // one per series
  tag(*p, "pv").set<double>(0.75);
  clock.run_until(10'000'000);
  EXPECT_DOUBLE_EQ(tag(*p, "y").get<double>(), 0.5);
  EXPECT_TRUE(tag(*p, "ok").get<bool>());
  EXPECT_FALSE(tag(*p, "alarm").get<bool>());
}

}  // namespace
}  // namespace syncplc
