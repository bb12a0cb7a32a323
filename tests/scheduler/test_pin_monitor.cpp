// Pin monitoring in virtual time (runtime/core/pin_monitor.hpp,
// Program::read_value, Program::block_instances): pins are copied for
// readers only while a lease a read extends runs, values come from the scan
// they say, a lapsed lease's leftovers are never given as live.
#include <gtest/gtest.h>

#include "runtime/core/virtual_clock.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

const char* kProject = R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: total, type: LREAL}
  - {name: gains, type: "ARRAY[1..2] OF LREAL"}
blocks:
  - {name: acc, type: ACC, task: fast, inputs: {IN: 1.0}}
  - {name: g, type: ARRAY_GAIN, task: slow, params: {N: 2}, inputs: {IN: [1.0, 2.0]}}
  - {name: add, type: ADD, task: slow, datatype: LREAL, inputs: {IN1: 1.0, IN2: 2.0}}
connections:
  - acc.SUM -> total
  - g.OUT -> gains
)";

TEST(PinMonitor, BlockInstancesListTheirPinsWithTypesUnitsAndCells) {
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  auto list = p->block_instances();
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[0].name, "acc");
  EXPECT_EQ(list[0].task, "fast");
  EXPECT_EQ(list[2].type, "ADD<LREAL>");
  const auto& g = list[1];
  EXPECT_EQ(g.name, "g");
  EXPECT_EQ(g.position, 0u);
  ASSERT_GE(g.pins.size(), 3u);
  EXPECT_EQ(g.pins[0].name, "IN");
  EXPECT_EQ(g.pins[0].dir, PinDir::In);
  EXPECT_EQ(g.pins[0].unit, "m");
  EXPECT_EQ(g.pins[0].cell.length, 2u);
  EXPECT_EQ(g.pins[1].dir, PinDir::Out);
  auto r = p->resolve("g.OUT");
  ASSERT_TRUE(r);
  EXPECT_EQ(g.pins[1].cell.task, r->task);
  EXPECT_EQ(g.pins[1].cell.cell, r->cell);
}

TEST(PinMonitor, PinsAreCopiedOnlyWhileSomeoneReadsThem) {
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  const auto pin = *p->resolve("acc.SUM");
  Cell v;
  auto at = p->read_value(pin, &v, 5'000'000);  // a 5 ms lease
  ASSERT_TRUE(at) << "before any scan the pins are the loaded ones";
  EXPECT_EQ(at->scan, 0u);
  EXPECT_EQ(v.get<double>(), 0.0);
  clock.run_until(3'000'000);  // scans at 0, 1 and 2 ms
  at = p->read_value(pin, &v, 5'000'000);
  ASSERT_TRUE(at);
  EXPECT_EQ(at->scan, 3u);
  EXPECT_EQ(at->release_ns, 2'000'000) << "the third scan was released at 2 ms (logical time)";
  EXPECT_EQ(v.get<double>(), 3.0);
  // Nobody reads for 50 ms: the lease lapses, the task stops copying.
  clock.run_until(53'000'000);
  EXPECT_FALSE(p->tasks[0]->pin_monitor().monitoring(p->tasks[0]->scan_count()));
  EXPECT_FALSE(p->read_value(pin, &v)) << "the copy is a lapsed lease's: not live";
  clock.run_until(54'000'000);  // this read renewed the lease: the next scan copies
  at = p->read_value(pin, &v);
  ASSERT_TRUE(at);
  EXPECT_EQ(at->scan, 54u);
  EXPECT_EQ(v.get<double>(), 54.0);
}

TEST(PinMonitor, ArrayPinsAndTagsReadFromTheirScan) {
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  Cell out[2];
  ASSERT_TRUE(p->read_value(*p->resolve("g.OUT"), out));
  clock.run_until(25'000'000);
  auto at = p->read_value(*p->resolve("g.OUT"), out);
  ASSERT_TRUE(at);
  EXPECT_EQ(at->scan, 3u);
  EXPECT_EQ(out[0].get<double>(), 2.0);
  EXPECT_EQ(out[1].get<double>(), 4.0);
  Cell one;
  ASSERT_TRUE(p->read_value(*p->resolve("g.OUT[2]"), &one));
  EXPECT_EQ(one.get<double>(), 4.0);
  // A tag: the owner's publication, whatever the lease.
  Cell total;
  at = p->read_value(*p->resolve("total"), &total);
  ASSERT_TRUE(at);
  EXPECT_EQ(at->scan, 25u);
  EXPECT_EQ(at->release_ns, 24'000'000) << "a tag's stamp: its publication's scan and release";
  EXPECT_EQ(total.get<double>(), 25.0);
}

}  // namespace
}  // namespace syncplc
