// UNIT_DELAY: OUT is IN of the previous scan.
#include <vector>

#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

TEST(UnitDelay, ShiftsSequenceByExactlyOneScan) {
  BlockHarness h(registry(), "UNIT_DELAY");
  ASSERT_HARNESS_OK(h);
  const std::vector<double> in{1.5, -2.0, 3.25, 3.25, 0.0, 7.0};
  std::vector<double> out;
  for (double v : in) {
    h.set<double>("IN", v);
    h.scan();
    out.push_back(h.get<double>("OUT"));
  }
  EXPECT_EQ(out, (std::vector<double>{0.0, 1.5, -2.0, 3.25, 3.25, 0.0}));
}

TEST(UnitDelay, OutputDoesNotDependOnThisScansInput) {
  BlockHarness h(registry(), "UNIT_DELAY", opts(IecType::INT));
  ASSERT_HARNESS_OK(h);
  h.set<std::int16_t>("IN", 5);
  h.scan();
  EXPECT_EQ(h.get<std::int16_t>("OUT"), 0);  // the type's zero on the first scan
  ScanContext ctx;
  h.set<std::int16_t>("IN", 9);
  h.block().execute(ctx);  // execute alone: OUT := state (5), IN not yet sampled
  EXPECT_EQ(h.get<std::int16_t>("OUT"), 5);
  h.set<std::int16_t>("IN", 11);  // a later block changes IN within the scan
  h.block().end_of_scan();  // sampled at the end of the scan
  h.block().execute(ctx);
  EXPECT_EQ(h.get<std::int16_t>("OUT"), 11);
}

TEST(UnitDelay, FeedbackCounter) {
  // OUT -> ADD(+1) -> IN: a counter through the delay.
  BlockHarness d(registry(), "UNIT_DELAY", opts(IecType::DINT));
  BlockHarness add(registry(), "ADD", opts(IecType::DINT, std::set<std::string>{"IN1", "IN2"}));
  add.set<std::int32_t>("IN2", 1);
  for (int k = 0; k < 5; ++k) {
    ScanContext ctx;
    d.block().execute(ctx);
    add.set<std::int32_t>("IN1", d.get<std::int32_t>("OUT"));
    add.block().execute(ctx);
    d.set<std::int32_t>("IN", add.get<std::int32_t>("OUT"));
    d.block().end_of_scan();
    EXPECT_EQ(d.get<std::int32_t>("OUT"), k);
  }
}

TEST(UnitDelay, BoolTimeAndWord) {
  BlockHarness b(registry(), "UNIT_DELAY", opts(IecType::BOOL));
  BlockHarness t(registry(), "UNIT_DELAY", opts(IecType::TIME));
  BlockHarness w(registry(), "UNIT_DELAY", opts(IecType::WORD));
  b.set<bool>("IN", true);
  t.set<std::int64_t>("IN", ms(3));
  w.set<std::uint16_t>("IN", 0x5A5A);
  for (auto* h : {&b, &t, &w}) h->scan();
  EXPECT_FALSE(b.get<bool>("OUT"));
  EXPECT_EQ(t.get<std::int64_t>("OUT"), 0);
  EXPECT_EQ(w.get<std::uint16_t>("OUT"), 0);
  b.set<bool>("IN", false);
  for (auto* h : {&b, &t, &w}) h->scan();
  EXPECT_TRUE(b.get<bool>("OUT"));
  EXPECT_EQ(t.get<std::int64_t>("OUT"), ms(3));
  EXPECT_EQ(w.get<std::uint16_t>("OUT"), 0x5A5A);
  b.scan();
  EXPECT_FALSE(b.get<bool>("OUT"));
}

TEST(UnitDelay, IsMarkedAsUnitDelay) {
  const auto* t = registry().find("UNIT_DELAY");
  ASSERT_NE(t, nullptr);
  EXPECT_TRUE(t->unit_delay);
  EXPECT_EQ(t->category, "execution control");
  // The only other unit delay is MC_AXIS: it makes its set values from the
  // drive's feedback of the scan before (docs/motion/plcopen.md).
  for (const auto* other : registry().all()) {
    if (other->name != "UNIT_DELAY" && other->name != "MC_AXIS") {
      EXPECT_FALSE(other->unit_delay) << other->name;
    }
  }
  ASSERT_NE(registry().find("MC_AXIS"), nullptr);
  EXPECT_TRUE(registry().find("MC_AXIS")->unit_delay);
}

}  // namespace
}  // namespace syncplc::iectest
