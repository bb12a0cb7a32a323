// TAYLOR_ESTIMATOR through BlockHarness: pins, parameters, and the same
// numbers as MessageEstimator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <map>
#include <string>

#include "fblocks/library.hpp"
#include "fblocks/motion/message_estimator.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::motion {
namespace {

BlockHarness make(std::map<std::string, std::string> params = {}) {
  BlockHarness::Options o;
  o.params = std::move(params);
  return BlockHarness(builtin_blocks(), "TAYLOR_ESTIMATOR", o);
}

std::string errors_of(const BlockHarness& h) {
  std::string s;
  for (const auto& e : h.errors()) s += e + "\n";
  return s;
}

TEST(TaylorEstimatorBlock, Declaration) {
  const BlockTypeInfo* t = builtin_blocks().find("TAYLOR_ESTIMATOR");
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->category, "Motion");
  for (const char* p : {"in", "valid", "out", "estimated", "consecutive", "next"}) EXPECT_GE(t->pin_index(p), 0) << p;
  for (const char* p : {"order", "history", "max_extrapolation"}) EXPECT_GE(t->param_index(p), 0) << p;
  EXPECT_NE(t->doc.find("21/8"), std::string::npos);
  EXPECT_NE(t->reference.find("paper 003"), std::string::npos);
  EXPECT_NE(t->reference.find("eq. (15)"), std::string::npos);
  EXPECT_TRUE(t->pins[static_cast<std::size_t>(t->pin_index("in"))].required);
}

// The loader checks the declared ranges; the factory refuses the rest too
// (BlockHarness passes parameters unchecked).
TEST(TaylorEstimatorBlock, OutOfRangeParametersAreErrors) {
  EXPECT_FALSE(make({{"order", "4"}}).ok());
  EXPECT_FALSE(make({{"order", "-1"}}).ok());
  EXPECT_FALSE(make({{"history", "3"}}).ok());
  EXPECT_TRUE(make({{"history", "2"}, {"order", "0"}}).ok());
}

TEST(TaylorEstimatorBlock, PassesValidSamplesAndEstimatesLostOnes) {
  auto h = make();
  ASSERT_TRUE(h.ok()) << errors_of(h);
  for (int k = 0; k < 6; ++k) {
    h.set<double>("in", 1.5 * k);
    h.set<bool>("valid", true);
    h.scan();
    EXPECT_EQ(h.get<double>("out"), 1.5 * k);
    EXPECT_FALSE(h.get<bool>("estimated"));
    EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 0u);
    // One sample: the prediction holds it; from two on the ramp is exact.
    EXPECT_DOUBLE_EQ(h.get<double>("next"), k == 0 ? 0.0 : 1.5 * (k + 1)) << k;
  }
  h.set<double>("in", -999.0);  // garbage while lost: ignored
  h.set<bool>("valid", false);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("out"), 9.0);
  EXPECT_TRUE(h.get<bool>("estimated"));
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 1u);
  h.scan();
  EXPECT_DOUBLE_EQ(h.get<double>("out"), 10.5);
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 2u);
  h.set<double>("in", 12.0);
  h.set<bool>("valid", true);
  h.scan();
  EXPECT_EQ(h.get<double>("out"), 12.0);
  EXPECT_FALSE(h.get<bool>("estimated"));
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 0u);
}

TEST(TaylorEstimatorBlock, DefaultsAreRobustOrder3) {
  const BlockTypeInfo* t = builtin_blocks().find("TAYLOR_ESTIMATOR");
  ASSERT_NE(t, nullptr);
  auto def = [&](const char* p) { return t->params[static_cast<std::size_t>(t->param_index(p))].default_value; };
  EXPECT_EQ(def("order"), "3");
  EXPECT_EQ(def("history"), "0");
  EXPECT_EQ(def("max_extrapolation"), std::to_string(MessageEstimator::kDefaultMaxExtrapolation));
  // valid left unconnected: every sample counts as received.
  const PinDecl& valid = t->pins[static_cast<std::size_t>(t->pin_index("valid"))];
  EXPECT_EQ(valid.init, "TRUE");
}

// The block is MessageEstimator: same outputs for every order and history.
TEST(TaylorEstimatorBlock, MatchesMessageEstimator) {
  for (int history = 0; history <= 2; ++history)
    for (int order = 0; order <= 3; ++order) {
      auto h = make({{"order", std::to_string(order)}, {"history", std::to_string(history)}, {"max_extrapolation", "6"}});
      ASSERT_TRUE(h.ok()) << errors_of(h);
      MessageEstimator ref(order, static_cast<EstimatorHistory>(history), 6);
      std::uint64_t s = 5;
      for (int k = 0; k < 2000; ++k) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        const bool valid = (s >> 33) % 100 >= 30;
        const double x = 10 * std::sin(0.003 * k);
        h.set<double>("in", x);
        h.set<bool>("valid", valid);
        h.scan();
        const double y = ref.update(valid, x);
        ASSERT_EQ(h.get<double>("out"), y) << order << " " << history << " " << k;
        ASSERT_EQ(h.get<bool>("estimated"), ref.estimated());
        ASSERT_EQ(h.get<std::uint32_t>("consecutive"), ref.consecutive());
        ASSERT_EQ(h.get<double>("next"), ref.predict_next());
      }
    }
}

TEST(TaylorEstimatorBlock, LongOutageHoldsAfterMaxExtrapolation) {
  auto h = make({{"max_extrapolation", "3"}});
  ASSERT_TRUE(h.ok()) << errors_of(h);
  for (int k = 0; k < 5; ++k) {
    h.set<double>("in", 2.0 * k);
    h.scan();
  }
  h.set<bool>("valid", false);
  double outs[6];
  for (double& o : outs) {
    h.scan();
    o = h.get<double>("out");
  }
  EXPECT_DOUBLE_EQ(outs[0], 10.0);
  EXPECT_DOUBLE_EQ(outs[2], 14.0);
  EXPECT_DOUBLE_EQ(outs[3], 14.0);  // held from the 4th estimate on
  EXPECT_DOUBLE_EQ(outs[5], 14.0);
  EXPECT_EQ(h.get<std::uint32_t>("consecutive"), 6u);
}

}  // namespace
}  // namespace syncplc::motion
