// SR (set-dominant) and RS (reset-dominant): full truth tables from both states.
#include "tests/iec/iec_test_util.hpp"

namespace syncplc::iectest {
namespace {

struct Row {
  bool q_before, s, r, q_after;
};

// Brings a fresh instance to q_before, then applies (s, r) for one scan.
bool apply(const char* type, const char* s_pin, const char* r_pin, bool q_before, bool s, bool r) {
  BlockHarness h(registry(), type);
  EXPECT_TRUE(h.ok()) << errors_of(h);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Q1"));  // starts FALSE
  if (q_before) {
    h.set<bool>(s_pin, true);
    h.set<bool>(r_pin, false);
    h.scan();
    EXPECT_TRUE(h.get<bool>("Q1"));
  }
  h.set<bool>(s_pin, s);
  h.set<bool>(r_pin, r);
  h.scan();
  return h.get<bool>("Q1");
}

TEST(Sr, SetDominantTable) {
  const Row table[] = {
      {false, false, false, false}, {false, false, true, false}, {false, true, false, true},
      {false, true, true, true},  // set wins
      {true, false, false, true},   {true, false, true, false},  {true, true, false, true},
      {true, true, true, true},
  };
  for (const auto& row : table)
    EXPECT_EQ(apply("SR", "S1", "R", row.q_before, row.s, row.r), row.q_after)
        << "Q=" << row.q_before << " S1=" << row.s << " R=" << row.r;
}

TEST(Rs, ResetDominantTable) {
  const Row table[] = {
      {false, false, false, false}, {false, false, true, false}, {false, true, false, true},
      {false, true, true, false},  // reset wins
      {true, false, false, true},   {true, false, true, false},  {true, true, false, true},
      {true, true, true, false},
  };
  for (const auto& row : table)
    EXPECT_EQ(apply("RS", "S", "R1", row.q_before, row.s, row.r), row.q_after)
        << "Q=" << row.q_before << " S=" << row.s << " R1=" << row.r;
}

TEST(Sr, HoldsStateAcrossScans) {
  BlockHarness h(registry(), "SR");
  h.set<bool>("S1", true);
  h.scan();
  h.set<bool>("S1", false);
  h.scans(10);
  EXPECT_TRUE(h.get<bool>("Q1"));
  h.set<bool>("R", true);
  h.scan();
  EXPECT_FALSE(h.get<bool>("Q1"));
  h.set<bool>("R", false);
  h.scans(3);
  EXPECT_FALSE(h.get<bool>("Q1"));
}

// Retained (docs/store.md): the latched Q1 comes back in a new instance and
// still obeys the table; a fresh one starts FALSE.
TEST(Sr, RetainedStateComesBackLatched) {
  for (const char* type : {"SR", "RS"}) {
    const bool sr = std::string(type) == "SR";
    BlockHarness a(registry(), type);
    a.set<bool>(sr ? "S1" : "S", true);
    a.scan();
    ASSERT_EQ(a.block().retain_cells(), 1u) << type;
    Cell state;
    a.block().save_retain(&state);
    BlockHarness b(registry(), type);
    b.block().load_retain(&state);
    b.scan();
    EXPECT_TRUE(b.get<bool>("Q1")) << type << ": restored latched with both inputs FALSE";
    b.set<bool>(sr ? "R" : "R1", true);
    b.scan();
    EXPECT_FALSE(b.get<bool>("Q1")) << type << ": and reset as before";
    BlockHarness fresh(registry(), type);
    fresh.scan();
    EXPECT_FALSE(fresh.get<bool>("Q1"));
  }
}

}  // namespace
}  // namespace syncplc::iectest
