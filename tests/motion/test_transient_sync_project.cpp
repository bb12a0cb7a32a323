// TRANSIENT_SYNC in a project: array pins given as list constants and
// connected whole to array tags, run by the virtual clock. Three axes start
// away from their references (start_at_r: false) and arrive together; with
// rule 2 they arrive apart and spend more energy.
#include <gtest/gtest.h>

#include <string>

#include "tests/support/image_key.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc {
namespace {

std::unique_ptr<Program> load(int rule) {
  const std::string text = R"(
tasks: [{name: main, period: 10ms}]
tags:
  - {name: x, type: "ARRAY[1..3] OF LREAL"}
  - {name: vmax, type: "ARRAY[1..3] OF LREAL"}
  - {name: sync, type: BOOL}
  - {name: e, type: LREAL}
  - {name: spread, type: LINT}
  - {name: windows, type: LINT}
blocks:
  - name: ts
    type: TRANSIENT_SYNC
    params: {n: 3, rule: )" + std::to_string(rule) + R"(, start_at_r: false}
    inputs:
      r: [2, -1, 0.5]
      r_dot: 0
      v_min: [-6, -5, -4]
      v_max: [6, 4, 5]
      a_min: [-25, -20, -30]
      a_max: [40, 25, 20]
connections:
  - ts.x -> x
  - ts.v_max_applied -> vmax
  - ts.synchronized -> sync
  - ts.energy_last -> e
  - ts.spread -> spread
  - ts.windows -> windows
)";
  LoadOptions o;
  auto r = load_project_text(text, "sync.yaml", o);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  return std::move(r.program);
}

double value(Program& p, const std::string& ref) {
  auto r = p.resolve(ref);
  EXPECT_TRUE(r) << ref;
  return r ? p.live_cell(*r, ::syncplc::testing::image_key())->get<double>() : 0.0;
}

TEST(TransientSyncProject, ArraysFromListConstantsAndTags) {
  auto sync = load(0), off = load(2);
  ASSERT_TRUE(sync);
  ASSERT_TRUE(off);
  VirtualClock cs(*sync), co(*off);
  cs.run_until(50'000'000);  // a few scans into the transient: axis 3 (0.5 m) runs on a reduced bound
  EXPECT_LT(value(*sync, "vmax[3]"), 5.0);
  EXPECT_EQ(value(*sync, "vmax[3]"), sync->live_cell(*sync->resolve("ts.v_max_applied[3]"), ::syncplc::testing::image_key())->get<double>());
  cs.run_until(3'000'000'000);
  co.run_until(3'000'000'000);
  for (Program* p : {sync.get(), off.get()}) {
    EXPECT_TRUE(p->live_cell(*p->resolve("sync"), ::syncplc::testing::image_key())->get<bool>());
    EXPECT_EQ(p->live_cell(*p->resolve("windows"), ::syncplc::testing::image_key())->get<std::int64_t>(), 1);
    EXPECT_NEAR(value(*p, "x[1]"), 2, 1e-9);
    EXPECT_NEAR(value(*p, "x[2]"), -1, 1e-9);
    EXPECT_NEAR(value(*p, "x[3]"), 0.5, 1e-9);
  }
  EXPECT_EQ(sync->live_cell(*sync->resolve("spread"), ::syncplc::testing::image_key())->get<std::int64_t>(), 0);
  EXPECT_GT(off->live_cell(*off->resolve("spread"), ::syncplc::testing::image_key())->get<std::int64_t>(), 10);
  EXPECT_GT(value(*sync, "e"), 0);
  EXPECT_LT(value(*sync, "e"), value(*off, "e"));
}

}  // namespace
}  // namespace syncplc
