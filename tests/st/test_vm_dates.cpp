// DT's day and time of day (DT_TO_DATE, DT_TO_TOD: IEC 61131-3 Table 22):
// floored, so a DT before 1970 has its own day; the first minutes DT holds
// have a day DATE does not (a fault, and DATE's first day); and every other
// conversion of a date type is refused by the checker with the way to build
// one.
#include <gmock/gmock.h>

#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace vm_dates {

using ::testing::HasSubstr;

TEST(StVmDates, ADateAndTimeSplitsIntoItsDayAndItsTimeOfDay) {
  auto r = run_program(
      "x, y, z : DT; d1, d2, d3 : DATE; t1, t2, t3 : TOD; ok1, ok2, ok3, ok4, ok5, ok6, back : BOOL;",
      "x := DT#2026-11-29-16:45:30.5; y := DT#1969-12-31-23:00:00; z := DT#1970-01-01-00:00:00;\n"
      "d1 := DT_TO_DATE(x); t1 := DT_TO_TOD(x);\n"
      "d2 := DT_TO_DATE(y); t2 := DT_TO_TOD(IN := y);\n"
      "d3 := DT_TO_DATE(z); t3 := DT_TO_TOD(z);\n"
      "ok1 := d1 = D#2026-11-29; ok2 := t1 = TOD#16:45:30.5;\n"
      "ok3 := d2 = D#1969-12-31; ok4 := t2 = TOD#23:00:00;\n"
      "ok5 := d3 = D#1970-01-01; ok6 := t3 = TOD#00:00:00;\n"
      // The day plus its time of day is the DT again.
      "back := DT#1970-01-01-00:00:00 + (d2 - D#1970-01-01) + (t2 - TOD#00:00:00) = y;");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  for (const char* ok : {"ok1", "ok2", "ok3", "ok4", "ok5", "ok6", "back"}) EXPECT_TRUE(r->get<bool>(ok)) << ok;
  EXPECT_TRUE(r->fault_texts().empty());
}

TEST(StVmDates, TheFirstMinutesOfDtHaveNoDateAndFault) {
  auto r = run_program("d : DATE; t : TOD; first : BOOL;",
                       "d := DT_TO_DATE(DT#1677-09-21-00:12:44);\nt := DT_TO_TOD(DT#1677-09-21-00:12:44);\n"
                       "first := d = D#1677-09-22;");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  EXPECT_TRUE(r->get<bool>("first"));
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 1u);
  EXPECT_THAT(f[0], HasSubstr("DT_TO_DATE: the day is before DATE's first (1677-09-22) at t0.st:5:6"));
}

TEST(StVmDates, OtherConversionsOfDatesAreRefusedWithTheWayToBuildOne) {
  auto r = std::make_unique<StRun>(
      std::vector<std::string>{"PROGRAM Main\nVAR\nd : DATE; n : LINT; s : STRING; t : TOD; x : DT;\nEND_VAR\n"
                               "d := LINT_TO_DATE(n);\nn := DATE_TO_LINT(d);\ns := DT_TO_STRING(x);\n"
                               "x := DATE_TO_DT(d);\nx := TO_DT(t);\nEND_PROGRAM\n"},
      "Main");
  ASSERT_EQ(r->errors.size(), 5u);
  EXPECT_THAT(r->errors[0], HasSubstr("t0.st:5:6: LINT_TO_DATE: a DATE, TOD or DT converts only as DT_TO_DATE and "
                                      "DT_TO_TOD (IEC 61131-3 Table 22); build one with its arithmetic: "
                                      "DT#1970-01-01-00:00:00 + T#..., TOD#00:00:00 + T#..."));
  EXPECT_THAT(r->errors[1], HasSubstr("t0.st:6:6: DATE_TO_LINT"));
  EXPECT_THAT(r->errors[2], HasSubstr("t0.st:7:6: DT_TO_STRING"));
  EXPECT_THAT(r->errors[3], HasSubstr("t0.st:8:6: DATE_TO_DT"));
  EXPECT_THAT(r->errors[4], HasSubstr("t0.st:9:6: TO_DT"));
}

}  // namespace vm_dates
}  // namespace syncplc::st::testing
