// DT's day and time of day (DT_TO_DATE, DT_TO_TOD: IEC 61131-3 Table 22):
// floored, so a DT before 1970 has its own day; the first minutes DT holds
// have a day DATE does not (a fault, and DATE's first day); every other
// conversion of a date type is refused by the checker with the way to build
// one. The functions of the time types (tables 35 and 36): the operators by
// name, and dates from their fields with a fault for a field out of range.
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

TEST(StVmDates, DtsFirstDayHasNoDateAndFaultsItsNeighboursDoNot) {
  auto r = run_program("d1, d2, d3 : DATE; ok : ARRAY[1..3] OF BOOL;",
                       "d1 := DT_TO_DATE(DT#1677-09-21-23:59:59.999999999);\n"
                       "d2 := DT_TO_DATE(DT#1677-09-22-00:00:00);\n"
                       "d3 := DT_TO_DATE(DT#2262-04-11-23:47:16.854775807);\n"
                       "ok[1] := d1 = D#1677-09-22; ok[2] := d2 = D#1677-09-22; ok[3] := d3 = D#2262-04-11;");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  for (int k = 1; k <= 3; ++k) EXPECT_TRUE(r->get<bool>("ok[" + std::to_string(k) + "]")) << k;
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 1u);  // the first only
  EXPECT_THAT(f[0], HasSubstr("at t0.st:5:7"));
}

TEST(StVmDates, TheEarliestDtHasNoDateAndFaults) {
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
                                      "DT_TO_TOD (IEC 61131-3 Table 22); build one from its fields (CONCAT_DATE, "
                                      "CONCAT_TOD, CONCAT_DT) or with its arithmetic (DT#1970-01-01-00:00:00 + T#...)"));
  EXPECT_THAT(r->errors[1], HasSubstr("t0.st:6:6: DATE_TO_LINT: a DATE, TOD or DT converts only as DT_TO_DATE and "
                                      "DT_TO_TOD (IEC 61131-3 Table 22); its number is a duration's: "
                                      "TIME_TO_LINT(x - D#1970-01-01) (milliseconds)"));
  EXPECT_THAT(r->errors[2], HasSubstr("t0.st:7:6: DT_TO_STRING"));
  EXPECT_THAT(r->errors[3], HasSubstr("t0.st:8:6: DATE_TO_DT"));
  EXPECT_THAT(r->errors[4], HasSubstr("t0.st:9:6: TO_DT"));
}

TEST(StVmDates, TheNamedFunctionsOfTheTimeTypesComputeAsTheOperators) {
  auto r = run_program(
      "ok : ARRAY[1..12] OF BOOL; n : INT := 4; k : LREAL := 2.5;",
      "ok[1] := ADD_TOD_TIME(TOD#23:00:00, T#30m) = TOD#23:30:00;\n"
      "ok[2] := ADD_DT_TIME(DT#2026-11-29-23:00:00, T#2h) = DT#2026-11-30-01:00:00;\n"
      "ok[3] := SUB_DT_DT(DT#2026-11-29-16:00:00, DT#2026-11-29-15:15:00) = T#45m;\n"
      "ok[4] := SUB_DATE_DATE(D#2026-11-29, D#2026-01-01) = T#332d;\n"
      "ok[5] := SUB_TOD_TOD(IN2 := TOD#08:00:00, IN1 := TOD#17:30:00) = T#9h30m;\n"
      "ok[6] := MUL_TIME(T#1s, k) = T#2.5s;\n"
      "ok[7] := DIV_TIME(T#1s, n) = T#250ms;\n"
      "ok[8] := ADD_TIME(T#1s, T#500ms) = SUB_TIME(T#2s, T#500ms);\n"
      "ok[9] := SUB_DT_TIME(DT#1970-01-01-00:00:00, T#1s) = DT#1969-12-31-23:59:59;\n"
      "ok[10] := SUB_TOD_TIME(TOD#00:30:00, T#15m) = TOD#00:15:00;\n"
      "ok[11] := CONCAT_DATE_TOD(D#2026-11-29, TOD#16:45:30.5) = DT#2026-11-29-16:45:30.5;\n"
      "ok[12] := MUL_TIME(T#1s, 3) = T#3s;");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  for (int k = 1; k <= 12; ++k) EXPECT_TRUE(r->get<bool>("ok[" + std::to_string(k) + "]")) << k;
  EXPECT_TRUE(r->fault_texts().empty());
}

TEST(StVmDates, DatesFromTheirFieldsAndTheDayOfTheWeek) {
  auto r = run_program(
      "ok : ARRAY[1..8] OF BOOL; y : DINT := 2026; m : USINT := 11; d : INT := 29; sun, wed, leap : INT;",
      "ok[1] := CONCAT_DATE(y, m, d) = D#2026-11-29;\n"
      "ok[2] := CONCAT_TOD(16, 45, 30, 500) = TOD#16:45:30.5;\n"
      "ok[3] := CONCAT_DT(2026, 11, 29, 16, 45, 30, 500) = DT#2026-11-29-16:45:30.5;\n"
      "ok[4] := CONCAT_DATE(YEAR := 2024, DAY := 29, MONTH := 2) = D#2024-02-29;\n"
      "ok[5] := CONCAT_DATE(1677, 9, 22) = D#1677-09-22;\n"
      "ok[6] := CONCAT_DT(2262, 4, 11, 23, 47, 16, 854) = DT#2262-04-11-23:47:16.854;\n"
      "ok[7] := CONCAT_DATE(1969, 12, 31) = D#1969-12-31;\n"
      "ok[8] := CONCAT_TOD(0, 0, 0, 0) = TOD#00:00:00;\n"
      "sun := DAY_OF_WEEK(D#2026-11-29); wed := DAY_OF_WEEK(D#1969-12-31); leap := DAY_OF_WEEK(D#2000-02-29);");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  for (int k = 1; k <= 8; ++k) EXPECT_TRUE(r->get<bool>("ok[" + std::to_string(k) + "]")) << k;
  EXPECT_EQ(r->get<std::int16_t>("sun"), 0);   // IEC: 0 is Sunday
  EXPECT_EQ(r->get<std::int16_t>("wed"), 3);
  EXPECT_EQ(r->get<std::int16_t>("leap"), 2);  // a Tuesday
  EXPECT_TRUE(r->fault_texts().empty());
}

TEST(StVmDates, AFieldOutOfItsRangeFaultsAndGivesTheEpoch) {
  auto r = run_program(
      "a, b : DATE; t : TOD; x, z : DT; q : TIME; zero : INT; epoch : ARRAY[1..5] OF BOOL;",
      "a := CONCAT_DATE(2026, 2, 29);\n"
      "b := CONCAT_DATE(1677, 9, 21);\n"
      "t := CONCAT_TOD(24, 0, 0, 0);\n"
      "x := CONCAT_DT(2262, 4, 11, 23, 47, 17, 0);\n"
      "z := CONCAT_DT(2026, 13, 1, 0, 0, 0, 0);\n"
      "q := DIV_TIME(T#1s, zero);\n"
      "epoch[1] := a = D#1970-01-01; epoch[2] := b = D#1970-01-01; epoch[3] := t = TOD#00:00:00;\n"
      "epoch[4] := x = DT#1970-01-01-00:00:00; epoch[5] := z = DT#1970-01-01-00:00:00;");
  ASSERT_TRUE(r->ok()) << r->errors.front();
  ASSERT_TRUE(r->scan());
  for (int k = 1; k <= 5; ++k) EXPECT_TRUE(r->get<bool>("epoch[" + std::to_string(k) + "]")) << k;
  const auto f = r->fault_texts();
  ASSERT_EQ(f.size(), 6u);
  EXPECT_THAT(f[0], HasSubstr("CONCAT_DATE: a field out of its range, or a date DATE does not hold at t0.st:5:6"));
  EXPECT_THAT(f[2], HasSubstr("CONCAT_TOD: a field out of its range"));
  EXPECT_THAT(f[3], HasSubstr("CONCAT_DT: a field out of its range, or a date DATE does not hold at t0.st:8:6"));
  EXPECT_THAT(f[5], HasSubstr("division by zero at t0.st:10:6"));
}

TEST(StVmDates, TheTimeFunctionsTakeTheirTypesOnly) {
  auto r = std::make_unique<StRun>(
      std::vector<std::string>{"PROGRAM Main\nVAR\nt : TOD; x : REAL; d : DATE;\nEND_VAR\n"
                               "t := ADD_TOD_TIME(T#1s, T#1s);\nd := CONCAT_DATE(2026, 11);\nd := CONCAT_DATE(2026, 11, x);\n"
                               "END_PROGRAM\n"},
      "Main");
  ASSERT_EQ(r->errors.size(), 3u);
  // No hint of a conversion that does not exist (TIME_TO_TOD).
  EXPECT_THAT(r->errors[0], ::testing::EndsWith("t0.st:5:19: IN1 of ADD_TOD_TIME: expected TOD, found TIME"));
  EXPECT_THAT(r->errors[1], HasSubstr("t0.st:6:6: CONCAT_DATE takes 3 argument(s), found 2"));
  EXPECT_THAT(r->errors[2], HasSubstr("t0.st:7:28: DAY of CONCAT_DATE: expected an integer (ANY_INT), found REAL"));
}

}  // namespace vm_dates
}  // namespace syncplc::st::testing
