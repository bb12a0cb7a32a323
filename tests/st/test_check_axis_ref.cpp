// The PLCopen MC blocks as the checker sees them (docs/st.md, "Motion
// control blocks"): their link `Axis` is IEC's VAR_IN_OUT Axis : AXIS_REF,
// given a variable of type AXIS_REF at every call; MC_GroupMoveAbsolute's
// `Axes` an ARRAY[1..n] OF AXIS_REF. Errors at their place.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fblocks/library.hpp"
#include "runtime/st/vm/block_signatures.hpp"
#include "tests/st/checker_fixture.hpp"

namespace syncplc::st::testing {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

// The program's errors, checked with every registered block (the MC blocks too).
std::vector<std::string> axis_errors(const std::string& vars, const std::string& body) {
  Checked c;
  const std::string text = "PROGRAM P\nVAR_EXTERNAL x : AXIS_REF; END_VAR\nVAR\n" + vars + "\nEND_VAR\n" + body +
                           "\nEND_PROGRAM\n";
  c.parsed.push_back(std::make_unique<ParseResult>(parse(text, SourceFile("t.st"))));
  for (const auto& d : c.parsed.back()->diagnostics.list()) ADD_FAILURE() << d.text();
  c.program = syncplc::st::check({&c.parsed.back()->unit}, vm::block_signatures(::syncplc::builtin_blocks()));
  return c.errors();
}

TEST(CheckAxisRef, McBlocksTakeTheirAxisAsAVarInOut) {
  EXPECT_THAT(axis_errors("pwr : MC_Power; mv : MC_MoveAbsolute; st : MC_ReadStatus; on : BOOL;",
                          "pwr(Axis := x, Enable := TRUE);\n"
                          "mv(Axis := x, Execute := pwr.Status, Position := 10.0, Velocity := 5.0);\n"
                          "st(Axis := x, Enable := TRUE);\non := st.Standstill;"),
              IsEmpty());
}

TEST(CheckAxisRef, TheAxisMustBeGivenAtEveryCall) {
  EXPECT_THAT(axis_errors("pwr : MC_Power;", "pwr(Axis := x, Enable := TRUE);\npwr(Enable := FALSE);"),
              ElementsAre("7:1: VAR_IN_OUT 'Axis' of pwr (MC_Power) must be given a variable"));
}

TEST(CheckAxisRef, OnlyAnAxisRefVariableIsAnAxis) {
  EXPECT_THAT(axis_errors("pwr : MC_Power; r : LREAL;", "pwr(Axis := r, Enable := TRUE);"),
              ElementsAre("6:13: VAR_IN_OUT 'Axis' of pwr (MC_Power): expected a variable of type AXIS_REF, found LREAL"));
  EXPECT_THAT(axis_errors("pwr : MC_Power;", "pwr(Axis := 1, Enable := TRUE);"),
              ElementsAre("6:13: VAR_IN_OUT 'Axis' of pwr (MC_Power) needs a variable, not a value"));
  // An AXIS_REF is no number.
  EXPECT_THAT(axis_errors("i : DINT;", "i := x + 1;"), ::testing::Not(IsEmpty()));
}

TEST(CheckAxisRef, AGroupMoveTakesAnArrayOfAxesAsLongAsN) {
  EXPECT_THAT(axis_errors("g : MC_GroupMoveAbsolute := (n := 2); axes : ARRAY[1..2] OF AXIS_REF;",
                          "axes[1] := x; axes[2] := x;\ng(Axes := axes, Execute := TRUE);"),
              IsEmpty());
  EXPECT_THAT(axis_errors("g : MC_GroupMoveAbsolute := (n := 3); axes : ARRAY[1..2] OF AXIS_REF;",
                          "g(Axes := axes, Execute := TRUE);"),
              ElementsAre("6:11: VAR_IN_OUT 'Axes' of g (MC_GroupMoveAbsolute (n := 3)): expected a variable of type "
                          "ARRAY[1..3] OF AXIS_REF, found ARRAY[1..2] OF AXIS_REF"));
}

TEST(CheckAxisRef, AFunctionBlockPassesItsAxisOn) {
  // The CODESYS way: an FB of the user's takes VAR_IN_OUT Axis : AXIS_REF
  // and hands it to the MC blocks it calls.
  Checked c;
  const std::string text = R"(FUNCTION_BLOCK AxisControl
VAR_IN_OUT Axis : AXIS_REF; END_VAR
VAR_INPUT on : BOOL; END_VAR
VAR pwr : MC_Power; END_VAR
pwr(Axis := Axis, Enable := on);
END_FUNCTION_BLOCK
PROGRAM P
VAR_EXTERNAL x : AXIS_REF; END_VAR
VAR ctl : AxisControl; END_VAR
ctl(Axis := x, on := TRUE);
ctl(on := FALSE);
END_PROGRAM
)";
  c.parsed.push_back(std::make_unique<ParseResult>(parse(text, SourceFile("t.st"))));
  c.program = syncplc::st::check({&c.parsed.back()->unit}, vm::block_signatures(::syncplc::builtin_blocks()));
  EXPECT_THAT(c.errors(), ElementsAre("11:1: VAR_IN_OUT 'Axis' of ctl (AxisControl) must be given a variable"));
}

}  // namespace
}  // namespace syncplc::st::testing
