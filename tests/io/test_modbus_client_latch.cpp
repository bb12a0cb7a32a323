// The modbus_client driver's scan side in virtual time: the exchange is
// replaced by results the test hands over (ModbusClientDriver::inject), and
// the driver's clock is the virtual clock. Staleness at once, the age of the
// data, the three reactions, events for every fault and recovery, the
// outputs handed over.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/modbus_client/modbus_client.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t ms = 1'000'000;
std::atomic<std::int64_t> g_now{0};
std::int64_t virtual_now() { return g_now.load(); }

std::string project(const std::string& reaction, const std::string& extra = "") {
  return R"(
tasks: [{name: main, period: 10ms}]
tags:
  - {name: v, type: "ARRAY[1..2] OF INT"}
  - {name: ok, type: BOOL}
  - {name: age, type: LREAL, unit: ms}
  - {name: err, type: UINT}
  - {name: reacting, type: BOOL}
  - {name: cmd, type: INT, safe: -7}
  - {name: cmd_ok, type: BOOL}
drivers:
  - name: io
    type: modbus_client
    devices: [{name: dev, port: 5020, stale_after: 50ms, reaction: )" +
         reaction + R"(}]
    groups:
      - {name: g, function: 3, address: 0, count: 2)" + extra + R"(}
      - {name: w, function: 6, address: 9}
    bind: {g: v, g_ok: ok, g_age: age, g_error: err, g_reaction: reacting, w: cmd, w_ok: cmd_ok}
)";
}

struct Rig {
  explicit Rig(const std::string& yaml) : p(load_test_project(yaml)) {
    d = dynamic_cast<ModbusClientDriver*>(p->drivers[0].driver.get());
    d->set_network(false);
    d->set_clock(&virtual_now);
    g_now = 0;
    std::string err;
    EXPECT_TRUE(p->open_drivers(&err)) << err;
    clock = std::make_unique<VirtualClock>(*p);
  }
  ~Rig() { p->close_drivers(); }
  // Runs the scans up to and including t, the driver's clock following.
  void run_to(std::int64_t t) {
    for (std::int64_t k = next; k <= t; k += 10 * ms) {
      g_now = k;
      clock->run_until(k, true);
    }
    next = (t / (10 * ms) + 1) * 10 * ms;
  }
  void good(std::int16_t a, std::int16_t b, std::int64_t stamp) {
    Cell v[2];
    v[0].set<std::int16_t>(a);
    v[1].set<std::int16_t>(b);
    d->inject(0, 0, stamp, v);
  }
  Cell tag(const std::string& name) { return tag_cell(*p, name); }
  std::vector<std::string> events() {
    std::vector<std::string> out;
    Event e;
    while (p->tasks[0]->pop_event(e)) out.push_back(std::string(event_kind_name(e.kind)) + " " + e.message);
    return out;
  }
  std::unique_ptr<Program> p;
  ModbusClientDriver* d = nullptr;
  std::unique_ptr<VirtualClock> clock;
  std::int64_t next = 0;
};

TEST(ModbusClientLatch, GoodRepliesAreTakenWithTheirAge) {
  Rig r(project("hold"));
  r.run_to(0);
  EXPECT_FALSE(r.tag("ok").get<bool>());
  EXPECT_EQ(r.tag("err").get<std::uint16_t>(), 268);  // no reply yet
  EXPECT_FALSE(r.tag("reacting").get<bool>());       // the stale time starts with the first failure
  r.good(11, -12, 5 * ms);
  r.run_to(20 * ms);
  EXPECT_TRUE(r.tag("ok").get<bool>());
  EXPECT_EQ(r.tag("err").get<std::uint16_t>(), 0);
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 11);
  EXPECT_EQ(tag_cell(*r.p, "v[2]").get<std::int16_t>(), -12);
  EXPECT_DOUBLE_EQ(r.tag("age").get<double>(), 15.0);  // now 20 ms, reply completed at 5 ms
  EXPECT_TRUE(r.events().empty());
  // A reply stamped after the latch read its clock (it came in between): age 0, never negative.
  r.good(13, -14, 40 * ms + 1);
  r.run_to(40 * ms);
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 13);
  EXPECT_EQ(r.tag("age").get<double>(), 0.0);
}

// What a reader of live values is told of the values channel (IoDriver::
// input_ok, the HTTP API's driver_not_ok): the group's ok at the newest
// latch; a status channel and an output channel are always ok.
TEST(ModbusClientLatch, InputOkFollowsTheReadGroupsOk) {
  Rig r(project("hold"));
  const int values = r.d->channel_index("g");
  ASSERT_GE(values, 0);
  r.run_to(0);
  EXPECT_FALSE(r.d->input_ok(values)) << "no reply yet";
  EXPECT_TRUE(r.d->input_ok(r.d->channel_index("g_ok"))) << "a status channel reports, it is not read";
  EXPECT_TRUE(r.d->input_ok(r.d->channel_index("w")));
  r.good(1, 2, 5 * ms);
  r.run_to(10 * ms);
  EXPECT_TRUE(r.d->input_ok(values));
  r.d->inject(0, code(ClientError::Timeout), 12 * ms, nullptr);
  EXPECT_TRUE(r.d->input_ok(values)) << "until a scan latches the failure";
  r.run_to(20 * ms);
  EXPECT_FALSE(r.d->input_ok(values));
  EXPECT_TRUE(r.d->input_ok(-1));
  EXPECT_TRUE(r.d->input_ok(10'000));
}

TEST(ModbusClientLatch, ATimeoutIsStaleAtOnceAndHoldKeepsTheValuesFlagged) {
  Rig r(project("hold"));
  r.good(1, 2, 0);
  r.run_to(10 * ms);
  EXPECT_TRUE(r.tag("ok").get<bool>());
  r.d->inject(0, code(ClientError::Timeout), 12 * ms, nullptr);
  r.run_to(20 * ms);  // the next scan sees it
  EXPECT_FALSE(r.tag("ok").get<bool>());
  EXPECT_EQ(r.tag("err").get<std::uint16_t>(), 256);
  EXPECT_FALSE(r.tag("reacting").get<bool>());
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 1);
  r.run_to(60 * ms);
  EXPECT_FALSE(r.tag("reacting").get<bool>());  // stale for 40 ms < stale_after 50 ms
  r.run_to(70 * ms);
  EXPECT_TRUE(r.tag("reacting").get<bool>());
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 1);  // held
  EXPECT_DOUBLE_EQ(r.tag("age").get<double>(), 70.0);
  // A different failure is a new event; the same one again is not.
  r.d->inject(0, code(ClientError::ConnectFailed), 72 * ms, nullptr);
  r.run_to(80 * ms);
  r.d->inject(0, code(ClientError::ConnectFailed), 82 * ms, nullptr);
  r.run_to(90 * ms);
  r.good(5, 6, 95 * ms);
  r.run_to(100 * ms);
  EXPECT_TRUE(r.tag("ok").get<bool>());
  EXPECT_FALSE(r.tag("reacting").get<bool>());
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 5);
  EXPECT_THAT(r.events(), ::testing::ElementsAre("driver-fault modbus_client io.g: timeout",
                                                 "driver-fault modbus_client io.g: stale past stale_after, holding the last values",
                                                 "driver-fault modbus_client io.g: connect failed",
                                                 "info modbus_client io.g: ok again"));
}

TEST(ModbusClientLatch, SafeSetsTheInputsToTheirSafeValuesWhileStale) {
  Rig r(project("safe", ", safe: [100, 200]"));
  r.run_to(0);
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 100);  // before the first reply
  r.good(1, 2, 0);
  r.run_to(10 * ms);
  EXPECT_EQ(tag_cell(*r.p, "v[2]").get<std::int16_t>(), 2);
  r.d->inject(0, code(ClientError::WrongTransaction), 15 * ms, nullptr);
  r.run_to(60 * ms);
  EXPECT_EQ(tag_cell(*r.p, "v[2]").get<std::int16_t>(), 2);  // stale, not yet stale_after
  r.run_to(70 * ms);
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 100);
  EXPECT_EQ(tag_cell(*r.p, "v[2]").get<std::int16_t>(), 200);
  EXPECT_EQ(r.tag("err").get<std::uint16_t>(), 263);
  r.good(3, 4, 75 * ms);
  r.run_to(80 * ms);
  EXPECT_EQ(tag_cell(*r.p, "v[1]").get<std::int16_t>(), 3);
}

TEST(ModbusClientLatch, StopStopsTheTaskWithItsSafeOutputs) {
  Rig r(project("stop"));
  r.good(1, 2, 0);
  r.run_to(0);
  tag_cell(*r.p, "cmd").set<std::int16_t>(42);  // a tag no block writes: set in the image
  r.run_to(10 * ms);
  const Cell* out = r.d->handed_over(1);
  ASSERT_NE(out, nullptr);
  EXPECT_EQ(out[0].get<std::int16_t>(), 42);
  r.d->inject(0, code(ClientError::ConnectionLost), 15 * ms, nullptr);
  r.run_to(100 * ms);
  EXPECT_TRUE(r.p->tasks[0]->stopped());
  out = r.d->handed_over(1);
  EXPECT_EQ(out[0].get<std::int16_t>(), -7);  // the tag's safe value went to the device's outputs
  const auto s = r.p->tasks[0]->stats.summary();
  EXPECT_EQ(s.scans, 8u);  // 0..70 ms: stale from 20 ms, stale_after 50 ms
  EXPECT_THAT(r.events(), ::testing::ElementsAre("driver-fault modbus_client io.g: connection lost",
                                                 "driver-fault modbus_client io.g: stale past stale_after, stopping the task",
                                                 "safe-state outputs driven to their safe values",
                                                 "task-stopped modbus_client io.g: stale past stale_after, stopping the task"));
}

TEST(ModbusClientLatch, TheSupervisorsSafeOutputsAreHeldAgainstLateWrites) {
  Rig r(project("hold"));
  tag_cell(*r.p, "cmd").set<std::int16_t>(5);
  r.run_to(0);
  SafeOutput s{r.d->channel_index("w"), 0, Cell{}};
  s.value.set<std::int16_t>(-1);
  EXPECT_TRUE(r.d->write_safe_outputs(&s, 1));
  EXPECT_EQ(r.d->handed_over(1)[0].get<std::int16_t>(), -1);
  r.run_to(20 * ms);  // later scans hand nothing over
  EXPECT_EQ(r.d->handed_over(1)[0].get<std::int16_t>(), -1);
}

double counter(const ModbusClientDriver& d, const std::string& name) {
  for (const auto& [k, v] : d.counters())
    if (k == name) return v;
  ADD_FAILURE() << "no counter " << name;
  return -1;
}
bool has_counter(const ModbusClientDriver& d, const std::string& name) {
  for (const auto& [k, v] : d.counters())
    if (k == name) return true;
  return false;
}

// The round trip counted to the scan that latched the reply, not to the
// reply: a reply waits for the next scan. Failures and replies no scan took
// (a newer one came first) are not counted in `latched`.
TEST(ModbusClientLatch, RoundTripsAreCountedFromTheRequestToTheLatchingScan) {
  Rig r(project("hold"));
  r.run_to(0);
  EXPECT_FALSE(has_counter(*r.d, "g.latched_p50_us"));  // nothing latched yet: no round trip to report
  Cell v[2];
  // Sent at 1 ms, in at 3 ms, latched by the scan at 10 ms: 2 ms and 9 ms.
  r.d->inject(0, 0, 3 * ms, v, 1 * ms);
  r.run_to(10 * ms);
  // A timeout between: neither counted.
  r.d->inject(0, code(ClientError::Timeout), 12 * ms, nullptr, 11 * ms);
  r.run_to(20 * ms);
  // Two replies before the scan at 30 ms: only the newer one is latched (30 - 27 = 3 ms).
  r.d->inject(0, 0, 22 * ms, v, 21 * ms);
  r.d->inject(0, 0, 28 * ms, v, 27 * ms);
  r.run_to(30 * ms);
  // Sent at 32, in at 35, latched at 40: 8 ms.
  r.d->inject(0, 0, 35 * ms, v, 32 * ms);
  r.run_to(40 * ms);
  EXPECT_DOUBLE_EQ(counter(*r.d, "g.latched_max_us"), 9000.0);
  EXPECT_NEAR(counter(*r.d, "g.latched_p50_us"), 8000.0, 8000.0 / 32);  // 3, 8, 9 ms
  EXPECT_NEAR(counter(*r.d, "g.latched_p99_us"), 9000.0, 9000.0 / 32);
  // `reply` is the device thread's part: request to reply, every success (2, 1, 1, 3 ms).
  EXPECT_DOUBLE_EQ(counter(*r.d, "g.reply_max_us"), 3000.0);
  EXPECT_NEAR(counter(*r.d, "g.reply_p50_us"), 2000.0, 2000.0 / 32);
  // Reopened: counted afresh.
  std::string err;
  ASSERT_TRUE(r.p->open_drivers(&err)) << err;
  EXPECT_FALSE(has_counter(*r.d, "g.latched_p50_us"));
}

// A reopened driver starts as a new one: the previous run's last reply is
// not latched as fresh, and its outputs are not handed over again.
TEST(ModbusClientLatch, AReopenedDriverServesNothingOfThePreviousRun) {
  Rig r(project("hold"));
  r.good(11, -12, 0);
  tag_cell(*r.p, "cmd").set<std::int16_t>(42);
  r.run_to(0);
  ASSERT_TRUE(r.tag("ok").get<bool>());
  ASSERT_NE(r.d->handed_over(1), nullptr);
  r.p->close_drivers();
  std::string err;
  ASSERT_TRUE(r.p->open_drivers(&err)) << err;
  EXPECT_EQ(r.d->handed_over(1), nullptr) << "no output of the previous run waits to be written";
  r.run_to(10 * ms);
  EXPECT_FALSE(r.tag("ok").get<bool>()) << "the previous run's reply is not fresh data";
  EXPECT_EQ(r.tag("err").get<std::uint16_t>(), 268);  // no reply yet
}

// Per-cycle freshness (as EtherCAT's working counter tells a frame's age):
// g_ok says the last exchange succeeded, g_cycles how many scans old the
// request of the values shown is: 0 for the reply to this cycle's request
// (sent after the previous scan's hand-over), n while no newer reply came.
TEST(ModbusClientLatch, CyclesSayHowManyScansOldTheValuesAre) {
  Rig r(R"(
tasks: [{name: main, period: 10ms}]
tags:
  - {name: v, type: "ARRAY[1..2] OF INT"}
  - {name: ok, type: BOOL}
  - {name: cycles, type: UDINT}
drivers:
  - name: io
    type: modbus_client
    devices: [{name: dev, port: 5020}]
    groups: [{name: g, function: 3, address: 0, count: 2}]
    bind: {g: v, g_ok: ok, g_cycles: cycles}
)");
  r.run_to(0);  // scan 0 latches (0 hand-overs so far), then hands over (1)
  EXPECT_FALSE(r.tag("ok").get<bool>());
  Cell v[2];
  r.d->inject(0, 0, 5 * ms, v, 1 * ms, 1, /*cycle=*/1);  // the request after scan 0's hand-over
  r.run_to(10 * ms);
  EXPECT_TRUE(r.tag("ok").get<bool>());
  EXPECT_EQ(r.tag("cycles").get<std::uint32_t>(), 0u);  // this cycle's
  r.run_to(40 * ms);  // three scans without a newer reply (a device slower than the task)
  EXPECT_TRUE(r.tag("ok").get<bool>()) << "ok: the last exchange succeeded";
  EXPECT_EQ(r.tag("cycles").get<std::uint32_t>(), 3u) << "...but its values are three scans old";
  r.d->inject(0, 0, 45 * ms, v, 41 * ms, 1, /*cycle=*/4);  // sent after scan 3's hand-over, in after scan 4's
  r.run_to(50 * ms);
  EXPECT_EQ(r.tag("cycles").get<std::uint32_t>(), 1u);
}

// The write gate's scan side: outputs handed over carry the connection on
// which every reading group of the device has good values latched (0: none
// yet, or one failed); a device without reads needs none (kAnyEpoch).
TEST(ModbusClientLatch, OutputsCarryTheConnectionTheirReadsCameFrom) {
  Rig r(project("hold"));
  r.run_to(0);
  EXPECT_EQ(r.d->handed_over_epoch(1), 0u);  // no reply yet: the device thread holds the write back
  Cell v[2];
  r.d->inject(0, 0, 5 * ms, v, 1 * ms, /*epoch=*/1);
  r.run_to(10 * ms);
  EXPECT_EQ(r.d->handed_over_epoch(1), 1u);
  r.d->inject(0, code(ClientError::ConnectionLost), 15 * ms, nullptr, 15 * ms, 1);
  r.run_to(20 * ms);
  EXPECT_EQ(r.d->handed_over_epoch(1), 0u);
  r.d->inject(0, 0, 25 * ms, v, 21 * ms, /*epoch=*/2);  // reconnected
  r.run_to(30 * ms);
  EXPECT_EQ(r.d->handed_over_epoch(1), 2u);
  auto p = load_test_project(R"(
tasks: [{name: main, period: 10ms}]
tags: [{name: cmd, type: INT}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: dev, port: 5020}]
    groups: [{name: w, function: 6, address: 0}]
    bind: {w: cmd}
)");
  auto* d = dynamic_cast<ModbusClientDriver*>(p->drivers[0].driver.get());
  d->set_network(false);
  std::string err;
  ASSERT_TRUE(p->open_drivers(&err)) << err;
  ScanContext ctx;
  d->latch_inputs(ctx);
  d->write_outputs(ctx);
  EXPECT_EQ(d->handed_over_epoch(0), GroupHandover::kAnyEpoch);
  p->close_drivers();
}

// Function 23 reads only with its write: an unbound write side is refused
// at open, with what to bind, instead of a group that never asks.
TEST(ModbusClientLatch, AFunction23GroupWithoutItsWriteBoundDoesNotOpen) {
  auto p = load_test_project(R"(
tasks: [{name: main, period: 10ms}]
tags: [{name: v, type: INT}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: dev, port: 5020}]
    groups: [{name: rw, function: 23, address: 0, write_address: 10}]
    bind: {rw: v}
)");
  auto* d = dynamic_cast<ModbusClientDriver*>(p->drivers[0].driver.get());
  d->set_network(false);
  std::string err;
  EXPECT_FALSE(p->open_drivers(&err));
  EXPECT_NE(err.find("request group rw (function 23) reads only with its write: bind rw_write"), std::string::npos) << err;
}

}  // namespace
}  // namespace syncplc
