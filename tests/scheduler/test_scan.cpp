// What one scan does, and in which order: inputs latched at the start,
// outputs written once after execution, snapshots between tasks, queued writes.
#include <gtest/gtest.h>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/memory_driver.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using testing::hook;
using testing::records;

const char* kIoProject = R"(
tasks: [{name: t, period: 1ms}]
tags:
  - {name: sensor, type: LREAL}
  - {name: actuator, type: LREAL}
blocks:
  - {name: before, type: RECORD}
  - {name: poke, type: HOOK}
  - {name: after, type: RECORD}
connections:
  - sensor -> before.IN
  - before.OUT -> poke.IN
  - poke.OUT -> after.IN
  - after.OUT -> actuator
drivers:
  - name: io
    type: memory
    channels:
      - {name: in, dir: in, type: LREAL}
      - {name: out, dir: out, type: LREAL}
    bind: {in: sensor, out: actuator}
)";

MemoryDriver& memory(Program& p, const std::string& name) {
  return dynamic_cast<MemoryDriver&>(*p.drivers[static_cast<std::size_t>(p.find_driver(name))].driver);
}

TEST(Scan, InputChangedDuringAScanIsSeenOnlyByTheNextScan) {
  records().clear();
  auto p = load_test_project(kIoProject);
  ASSERT_TRUE(p);
  auto& io = memory(*p, "io");
  // In scan 2 the field input changes while the program executes.
  hook() = [&](ScanContext& ctx) {
    if (ctx.scan == 2) {
      Cell c;
      c.set<double>(42.0);
      io.force_input(0, &c);
    }
  };
  VirtualClock clock(*p);
  clock.run_until(5'000'000);
  hook() = nullptr;
  std::vector<double> before, after;
  for (const auto& r : records()) (r.instance == "before" ? before : after).push_back(r.in);
  EXPECT_EQ(before, (std::vector<double>{0, 0, 0, 42, 42}));
  EXPECT_EQ(after, (std::vector<double>{0, 0, 0, 42, 42}));  // a block after the change in the same scan: still 0
}

TEST(Scan, OutputsAreWrittenOncePerScanAfterExecution) {
  records().clear();
  auto p = load_test_project(kIoProject);
  ASSERT_TRUE(p);
  auto& io = memory(*p, "io");
  std::vector<std::uint64_t> writes_seen_during_execution;
  std::vector<double> output_seen_during_execution;
  hook() = [&](ScanContext&) {
    writes_seen_during_execution.push_back(io.writes());
    Cell c;
    io.read_output(1, &c);
    output_seen_during_execution.push_back(c.get<double>());
  };
  Cell in;
  VirtualClock clock(*p);
  for (int k = 0; k < 4; ++k) {
    in.set<double>(10.0 * (k + 1));
    io.force_input(0, &in);
    clock.run_until(1'000'000 * k, true);
    Cell out;
    io.read_output(1, &out);
    EXPECT_EQ(out.get<double>(), 10.0 * (k + 1));  // written after the scan that computed it
  }
  hook() = nullptr;
  EXPECT_EQ(io.writes(), 4u);
  EXPECT_EQ(io.latches(), 4u);
  // During scan k the driver had been written k times and still held scan k-1's output.
  EXPECT_EQ(writes_seen_during_execution, (std::vector<std::uint64_t>{0, 1, 2, 3}));
  EXPECT_EQ(output_seen_during_execution, (std::vector<double>{0, 10, 20, 30}));
}

// Task "fast" publishes four values computed together; "slow" reads them.
std::string snapshot_project(int fast_priority, int slow_priority) {
  return R"(
tasks:
  - {name: fast, period: 1ms, priority: )" + std::to_string(fast_priority) + R"(}
  - {name: slow, period: 5ms, priority: )" + std::to_string(slow_priority) + R"(}
tags:
  - {name: stamp, type: "ARRAY[0..3] OF LREAL"}
blocks:
  - {name: st, type: STAMP, task: fast}
  - {name: r0, type: RECORD, task: slow}
  - {name: poke, type: HOOK, task: slow}
  - {name: r3, type: RECORD, task: slow}
connections:
  - st.A -> stamp[0]
  - st.B -> stamp[1]
  - st.C -> stamp[2]
  - st.D -> stamp[3]
  - stamp[0] -> r0.IN
  - stamp[3] -> r3.IN
)";
}

// Logical execution time: a scan released at t reads, from another task, the
// newest scan whose outputs are visible at t: the one released at t - 1 ms
// here (visible one producer period after its release), whichever task runs
// first at a shared instant.
void expect_let_values(int fast_priority, int slow_priority) {
  records().clear();
  auto p = load_test_project(snapshot_project(fast_priority, slow_priority));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(20'000'000);
  for (const auto& r : records()) {
    double want = r.now_ns == 0 ? 0.0 : static_cast<double>(r.now_ns) / 1e6 - 1.0;  // the initial 0 at first
    EXPECT_EQ(r.in, want) << r.instance << " at " << r.now_ns;
  }
  EXPECT_EQ(records().size(), 8u);
}

TEST(Scan, CrossTaskValuesAreThoseVisibleAtTheReleaseWithTheProducerFirst) { expect_let_values(90, 10); }
TEST(Scan, CrossTaskValuesAreThoseVisibleAtTheReleaseWithTheProducerAfter) { expect_let_values(10, 90); }

TEST(Scan, AProducerThatTakesLongerStillGivesTheSameValues) {
  // Virtual execution time inside the producer's period changes nothing the
  // consumer reads (the values are those visible at its release).
  records().clear();
  auto p = load_test_project(snapshot_project(10, 90));
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(20'000'000);
  auto plain = records();
  records().clear();
  std::string text = snapshot_project(10, 90);
  text.replace(text.find("  - {name: r0,"), 0, "  - {name: slow_down, type: BURN, task: fast, inputs: {EXEC: 900us}}\n");
  auto q = load_test_project(text);
  ASSERT_TRUE(q);
  VirtualClock c2(*q);
  c2.run_until(20'000'000);
  ASSERT_EQ(records().size(), plain.size());
  for (std::size_t i = 0; i < plain.size(); ++i) EXPECT_EQ(records()[i].in, plain[i].in) << i;
}

TEST(Scan, ValuesLatchedAtStartDoNotChangeDuringTheScan) {
  // The producer publishes while the consumer is mid-scan: the consumer keeps
  // its latched copy until its next scan. The hook runs the producer's scan
  // in the middle of the consumer's execution.
  records().clear();
  auto p = load_test_project(snapshot_project(10, 90));
  ASSERT_TRUE(p);
  Task& fast = *p->tasks[0];
  hook() = [&](ScanContext&) {
    ScanContext ctx;
    ctx.now_ns = 999'000'000;
    fast.scan(ctx);
    fast.publish();
  };
  VirtualClock clock(*p);
  clock.run_until(1);
  hook() = nullptr;
  ASSERT_EQ(records().size(), 2u);
  EXPECT_EQ(records()[0].in, 0.0);
  EXPECT_EQ(records()[1].in, 0.0);  // not 999: the value was latched before execution
}

TEST(Scan, QueuedWritesApplyAtTheNextScanStartInArrivalOrder) {
  records().clear();
  auto p = load_test_project(R"(
tasks: [{name: t, period: 1ms}]
tags:
  - {name: setpoint, type: LREAL, hmi: readwrite}
  - {name: pair, type: "ARRAY[0..1] OF DINT", hmi: readwrite}
blocks: [{name: r, type: RECORD}]
connections: [setpoint -> r.IN]
)");
  ASSERT_TRUE(p);
  VirtualClock clock(*p);
  clock.run_until(2'000'000);  // scans at 0 and 1 ms
  const Tag* sp = p->find_tag("setpoint");
  Cell a, b;
  a.set<double>(1.5);
  b.set<double>(2.5);
  ASSERT_TRUE(p->write_tag(*sp, 0, &a, 1));
  ASSERT_TRUE(p->write_tag(*sp, 0, &b, 1));  // the later write wins
  const Tag* pair = p->find_tag("pair");
  Cell two[2];
  two[0].set<std::int32_t>(7);
  two[1].set<std::int32_t>(-7);
  ASSERT_TRUE(p->write_tag(*pair, 0, two, 2));
  EXPECT_FALSE(p->write_tag(*pair, 1, two, 2));  // past the end: refused
  EXPECT_FALSE(p->write_tag(*pair, 0xFFFFFFFFu, two, 2));  // an index that would wrap around: refused
  EXPECT_FALSE(p->write_tag(*pair, 0, two, 0));
  clock.run_until(3'000'000);
  ASSERT_EQ(records().size(), 3u);
  EXPECT_EQ(records()[1].in, 0.0);
  EXPECT_EQ(records()[2].in, 2.5);
  Cell out[2];
  p->read_tag(*pair, out);
  EXPECT_EQ(out[0].get<std::int32_t>(), 7);
  EXPECT_EQ(out[1].get<std::int32_t>(), -7);
  EXPECT_EQ(p->tasks[0]->stats.summary().writes_applied, 4u);
}

TEST(Scan, AFullWriteQueueRefusesTheWholeBatch) {
  auto p = load_test_project(R"(
tasks: [{name: t, period: 1ms, write_queue: 16}]
tags: [{name: v, type: "ARRAY[0..31] OF INT", hmi: readwrite}]
)");
  ASSERT_TRUE(p);
  const Tag* v = p->find_tag("v");
  std::vector<Cell> vals(32);
  for (int i = 0; i < 32; ++i) vals[static_cast<std::size_t>(i)].set<std::int16_t>(static_cast<std::int16_t>(i));
  EXPECT_FALSE(p->write_tag(*v, 0, vals.data(), 32));  // more than the queue holds
  EXPECT_TRUE(p->write_tag(*v, 0, vals.data(), 10));
  EXPECT_FALSE(p->write_tag(*v, 10, vals.data() + 10, 10));  // 10 + 10 > 16: nothing of it queued
  VirtualClock clock(*p);
  clock.run_until(1);
  Cell out[32];
  p->read_tag(*v, out);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(out[i].get<std::int16_t>(), i);
  for (int i = 10; i < 32; ++i) EXPECT_EQ(out[i].get<std::int16_t>(), 0);
}

}  // namespace
}  // namespace syncplc
