// The quality of a live value (runtime/web/value_quality.hpp) and the ticks
// of a live stream (runtime/web/live_values.hpp): every value with its
// quality, the logical time of the scan that made it and its age; an unknown
// reference answered for itself while the others go on.
#include <gtest/gtest.h>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"
#include "runtime/web/live_values.hpp"
#include "runtime/web/value_quality.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc::web {
namespace live_values_test {

TEST(ValueQuality, TheWorstThatAppliesInOneWord) {
  QualityInputs in;
  in.stamp = ValueStamp{5, 40'000'000};
  in.now_ns = 41'000'000;
  in.period_ns = 10'000'000;
  EXPECT_EQ(judge_value(in).quality, Quality::Good);
  EXPECT_EQ(judge_value(in).age_ns, 1'000'000);
  in.forced = true;
  EXPECT_EQ(judge_value(in).quality, Quality::Forced);
  in.driver_ok = false;
  EXPECT_EQ(judge_value(in).quality, Quality::DriverNotOk) << "a failed exchange outweighs a force";
  // Three periods and a tenth of a second without a newer scan: stale.
  in.now_ns = 40'000'000 + stale_after_ns(10'000'000);
  EXPECT_EQ(judge_value(in).quality, Quality::DriverNotOk) << "exactly at the bound: not yet stale";
  in.now_ns += 1;
  EXPECT_EQ(judge_value(in).quality, Quality::Stale);
  EXPECT_EQ(judge_value(in).age_ns, stale_after_ns(10'000'000) + 1);
  in.task_stopped = true;
  EXPECT_EQ(judge_value(in).quality, Quality::TaskStopped) << "a stopped task's values never change again";
}

TEST(ValueQuality, NoScanYetIsStaleAndAnUnknownNowJudgesNoAge) {
  QualityInputs in;
  in.period_ns = 1'000'000;
  in.now_ns = 5'000'000;
  in.stamp = ValueStamp{0, 0};
  EXPECT_EQ(judge_value(in).quality, Quality::Stale) << "the value as loaded, not made by any scan";
  EXPECT_EQ(judge_value(in).age_ns, 0);
  in.stamp = ValueStamp{3, 2'000'000};
  in.now_ns = -1;  // no scheduler runs the program in real time
  EXPECT_EQ(judge_value(in).quality, Quality::Good);
  EXPECT_EQ(judge_value(in).age_ns, 0);
  in.now_ns = 1'000'000;  // the value read after `now`: a newer scan than now, never a negative age
  EXPECT_EQ(judge_value(in).age_ns, 0);
  EXPECT_STREQ(quality_name(Quality::TaskStopped), "task_stopped");
  EXPECT_STREQ(quality_name(Quality::DriverNotOk), "driver_not_ok");
}

const char* kProject = R"(project: {name: live}
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: count, type: LREAL, hmi: read}
  - {name: level, type: LREAL, hmi: read}
  - {name: levels, type: "ARRAY[1..3] OF INT", hmi: read, init: [1, 2, 3]}
  - {name: secret, type: INT}
blocks:
  - {name: up, type: ACC, task: fast, inputs: {IN: 1.0}}
  - {name: k, type: MOVE, task: slow, inputs: {IN: 2.5}}
connections:
  - up.SUM -> count
  - k.OUT -> level
)";

// A driver whose input channel 0 ("level_in") is bound to `level`, its
// exchange good or not as the test says.
class LinkDriver final : public IoDriver {
 public:
  LinkDriver() { channels_.push_back(DriverChannel{"level_in", PinDir::In, IecType::LREAL, 1, "", ""}); }
  const std::vector<DriverChannel>& channels() const override { return channels_; }
  void bind(const std::vector<Cell*>&) override {}
  bool open(std::string*) override { return true; }
  void latch_inputs(const ScanContext&) noexcept override {}
  void write_outputs(const ScanContext&) noexcept override {}
  void close() noexcept override {}
  bool write_safe_outputs(const SafeOutput*, std::size_t) noexcept override { return true; }
  bool input_ok(int channel) const noexcept override { return channel != 0 || ok; }
  bool ok = true;

 private:
  std::vector<DriverChannel> channels_;
};

struct Live {
  LoadResult r;
  Program* p = nullptr;
  LinkDriver* link = nullptr;
  Live() : r(load_test_result(kProject)) {
    if (!r.ok()) return;
    p = r.program.get();
    auto d = std::make_unique<LinkDriver>();
    link = d.get();
    d->set_name("io");
    DriverBinding b;
    b.driver = std::move(d);
    b.type = "link";
    b.task = p->tasks[static_cast<std::size_t>(p->find_task("slow"))]->index();
    b.bound_tags = {"level"};
    b.cells = {nullptr};
    p->drivers.push_back(std::move(b));
  }
  // The program's time axis as if a real-time scheduler ran it and it were `t_ns` now.
  void now_is(std::int64_t t_ns) { p->epoch_ns.store(monotonic_ns() - t_ns, std::memory_order_release); }
};

TEST(LiveValues, EveryValueCarriesItsQualityAndTheLogicalTimeOfItsScan) {
  Live live;
  ASSERT_TRUE(live.p);
  VirtualClock clock(*live.p);
  clock.run_until(50'000'000);  // fast: scans at 0..49 ms; slow: 0..40 ms
  live.now_is(50'000'000);
  LiveRefs refs;
  refs.set_refs({"count", "level", "levels[2]", "up.SUM"});
  nlohmann::json t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["values"]["count"], 50);
  EXPECT_EQ(t["quality"]["count"]["q"], "good");
  EXPECT_EQ(t["quality"]["count"]["scan_ns"], 49'000'000) << "the scan released at 49 ms made it";
  EXPECT_EQ(t["quality"]["level"]["scan_ns"], 40'000'000) << "the slow task's last scan";
  EXPECT_GE(t["quality"]["level"]["age_ns"].get<std::int64_t>(), 10'000'000);
  EXPECT_EQ(t["values"]["levels[2]"], 2);
  EXPECT_FALSE(t.contains("errors"));
  // A pin: absent while its monitoring starts, then with its scan's stamp.
  clock.run_until(51'000'000);
  live.now_is(51'000'000);
  t = refs.tick(*live.p, 1, nullptr);
  ASSERT_TRUE(t["values"].contains("up.SUM"));
  EXPECT_EQ(t["values"]["up.SUM"], 51);
  EXPECT_EQ(t["quality"]["up.SUM"]["scan_ns"], 50'000'000);

  // The driver bound to `level` loses its link: that value says so, no other.
  live.link->ok = false;
  t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["quality"]["level"]["q"], "driver_not_ok");
  EXPECT_EQ(t["quality"]["count"]["q"], "good");
  live.link->ok = true;

  // Forced: flagged in `forced` and in the quality.
  ASSERT_TRUE(live.p->force("levels[2]", "9").ok);
  clock.run_until(53'000'000);
  live.now_is(53'000'000);
  t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["values"]["levels[2]"], 9);
  EXPECT_EQ(t["quality"]["levels[2]"]["q"], "forced");
  EXPECT_EQ(t["forced"]["levels[2]"], true);

  // Nothing newer for longer than three periods and 100 ms: stale, with its age.
  live.now_is(253'000'000);
  t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["quality"]["count"]["q"], "stale");
  EXPECT_GT(t["quality"]["count"]["age_ns"].get<std::int64_t>(), 200'000'000);

  // The task stopped: its values say so; the other task's do not.
  live.now_is(53'000'000);
  live.p->tasks[0]->stop_from_supervisor();
  t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["quality"]["count"]["q"], "task_stopped");
  EXPECT_EQ(t["quality"]["level"]["q"], "good");
  // No scheduler runs the program: every task counts as stopped.
  live.p->epoch_ns.store(-1);
  t = refs.tick(*live.p, 1, nullptr);
  EXPECT_EQ(t["quality"]["level"]["q"], "task_stopped");
  EXPECT_EQ(t["now_ns"], -1);
}

TEST(LiveValues, AnUnknownOrHiddenRefIsAnsweredForItselfAndTheOthersGoOn) {
  Live live;
  ASSERT_TRUE(live.p);
  VirtualClock clock(*live.p);
  clock.run_until(5'000'000);
  live.now_is(5'000'000);
  const HiddenCells hidden(*live.p);
  LiveRefs refs;
  refs.set_refs({"count", "nope", "secret", "levels[7]"});
  nlohmann::json t = refs.tick(*live.p, 1, &hidden);
  EXPECT_EQ(t["values"]["count"], 5);
  ASSERT_TRUE(t.contains("errors"));
  EXPECT_NE(t["errors"]["nope"].get<std::string>().find("nope"), std::string::npos) << t.dump();
  EXPECT_NE(t["errors"]["secret"].get<std::string>().find("hmi: none"), std::string::npos) << t.dump();
  EXPECT_TRUE(t["errors"].contains("levels[7]")) << "an index outside the bounds";
  EXPECT_FALSE(t["values"].contains("secret"));
  // An engineer (no hidden cells) sees `secret`.
  t = refs.tick(*live.p, 2, nullptr);
  EXPECT_TRUE(t["values"].contains("secret"));

  // describe_ref: what a subscriber is told of each reference.
  const auto d = describe_ref(*live.p, nullptr, "level");
  EXPECT_EQ(d["task"], "slow");
  EXPECT_EQ(d["period_ns"], 10'000'000);
  EXPECT_EQ(d["type"], "LREAL");
  EXPECT_EQ(d["driver"], "io") << "bound to the test's driver";
  EXPECT_TRUE(describe_ref(*live.p, nullptr, "nope").contains("error"));
  EXPECT_TRUE(describe_ref(*live.p, &hidden, "secret").contains("error"));
}

TEST(LiveValues, AnOnlineChangeResolvesTheRefsAgain) {
  Live live;
  ASSERT_TRUE(live.p);
  VirtualClock clock(*live.p);
  clock.run_until(3'000'000);
  live.now_is(3'000'000);
  LiveRefs refs;
  refs.set_refs({"count", "level"});
  EXPECT_FALSE(refs.tick(*live.p, 1, nullptr).contains("errors"));
  // The next program has no `level` (renamed): answered for itself from the next generation.
  std::string next = kProject;
  next.replace(next.find("{name: level,"), 13, "{name: height,");
  next.replace(next.find("k.OUT -> level"), 14, "k.OUT -> height");
  LoadResult other = load_test_result(next);
  ASSERT_TRUE(other.ok());
  VirtualClock clock2(*other.program);
  clock2.run_until(3'000'000);
  other.program->epoch_ns.store(monotonic_ns() - 3'000'000);
  nlohmann::json t = refs.tick(*other.program, 2, nullptr);
  EXPECT_EQ(t["values"]["count"], 3);
  ASSERT_TRUE(t.contains("errors"));
  EXPECT_TRUE(t["errors"].contains("level"));
}

}  // namespace live_values_test
}  // namespace syncplc::web
