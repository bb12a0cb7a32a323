// Structured Text in a project: sources:, FUNCTION_BLOCKs as block types,
// programs:, VAR_EXTERNAL wired to tags, and the errors of each at their place.
#include "runtime/project/scan_test.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace st_sources {

using ::testing::HasSubstr;

std::string report_text(const ScanTestReport& r) {
  std::string s;
  for (const auto& d : r.diagnostics.sorted()) s += d.text() + "\n";
  for (const auto& c : r.cases)
    for (const auto& f : c.failures) s += c.name + ": " + f + "\n";
  return s;
}

TEST(StSources, ProgramsAndStBlocksRunWithBuiltInBlocksOrderedByTheirDataFlow) {
  temp_file("st_ok/logic.st", R"(
(* Counts the scans while enabled; doubles a tag. *)
PROGRAM Counting
VAR_EXTERNAL
  enable : BOOL;
  count : DINT;
  level : LREAL;
  doubled : LREAL;
END_VAR
VAR scans : DINT; t : TON; END_VAR
IF enable THEN
  count := count + 1;
END_IF;
doubled := level * 2.0;
scans := scans + 1;
t(IN := enable, PT := T#25ms);
END_PROGRAM

(* Scales its input, and counts its calls through an external. *)
FUNCTION_BLOCK Scale
VAR_INPUT x : LREAL; k : LREAL := 3.0; END_VAR
VAR_OUTPUT y : LREAL; END_VAR
VAR_EXTERNAL calls : DINT; END_VAR
VAR hist : ARRAY[1..3] OF LREAL; END_VAR
y := x * k;
calls := calls + 1;
hist[3] := hist[2]; hist[2] := hist[1]; hist[1] := DINT_TO_LREAL(calls);
END_FUNCTION_BLOCK
)");
  const std::string project = temp_file("st_ok/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [logic.st]
tags:
  - {name: enable, type: BOOL, hmi: readwrite}
  - {name: count, type: DINT}
  - {name: level, type: LREAL}
  - {name: doubled, type: LREAL}
  - {name: scaled, type: LREAL}
  - {name: calls, type: DINT, init: 100}
  - {name: ramp_out, type: LREAL}
programs:
  - {name: counting, type: Counting, task: main}
blocks:
  - {name: scale, type: Scale}
  - {name: ramp, type: ADD, inputs: {IN2: 1.0}}
connections:
  - doubled -> scale.x
  - scale.y -> scaled
  - ramp_out -> ramp.IN1
  - ramp.OUT -> level
traces: [counting.t.ET, "scale.hist[2]"]
)"));
  const std::string tests = temp_file("st_ok/t.yaml", yaml(R"(
cases:
  - name: ST and blocks together
    steps:
      - at: 0ms
        expect: {count: 0, calls: 101, doubled: 2.0, scaled: 6.0}
      - at: 10ms
        set: {enable: TRUE}
        expect: {count: 1, calls: 102}
      - at: 50ms
        expect: {count: 5, calls: 106, counting.scans: 6, counting.t.Q: TRUE, counting.t.ET: 25ms,
                 "scale.hist[1]": 106.0, "scale.hist[3]": 104.0, scale.k: 3.0}
      - at: 60ms
        set: {enable: FALSE, counting.scans: 100}
        expect: {counting.t.Q: FALSE, counting.scans: 101}
      - at: 70ms
        expect: {counting.scans: 102}
)"));
  const auto r = run_scan_tests(project, tests);
  EXPECT_TRUE(r.ok()) << report_text(r);
  auto l = load_project(project);
  ASSERT_LOADS(l);
  // The program writes count and doubled: it owns them, as a block owns what it writes.
  EXPECT_EQ(l.program->find_tag("count")->writer, "block counting.count");
  EXPECT_EQ(l.program->find_tag("calls")->writer, "block scale.calls");
  ASSERT_EQ(l.program->traces.size(), 2u);
  EXPECT_EQ(l.program->traces[0].label, "counting.t.ET");
  // instance.var where tags and pins are named: the variables of an ST instance, nested too.
  std::string why;
  ASSERT_TRUE(l.program->resolve("counting.t.ET", &why)) << why;
  EXPECT_EQ(l.program->resolve("counting.t.ET")->type, IecType::TIME);
  EXPECT_FALSE(l.program->resolve("counting.scanz", &why));
  EXPECT_EQ(why, "counting.scanz: Counting has no variable 'scanz' (did you mean scans?)");
  EXPECT_FALSE(l.program->resolve("scale.hist", &why));
  EXPECT_EQ(why, "scale.hist: it is a ARRAY[1..3] OF LREAL: address one of its elements or fields");
  EXPECT_FALSE(l.program->resolve("scale.hist[4]", &why));
  EXPECT_EQ(why, "scale.hist[4]: 'hist[4]': index 4 is outside 1..3");
}

// project: st_engine chooses how the sources run; both engines pass the
// same scan-cycle test, and `syncplc check` (LoadResult::st) says which ran.
TEST(StSources, TheProjectChoosesTheEngineAndBothPassTheSameScanTest) {
  temp_file("st_engine/window.st", R"(
FUNCTION_BLOCK Window
VAR_INPUT x : LREAL; END_VAR
VAR_OUTPUT sum, peak : LREAL; END_VAR
VAR buf : ARRAY[0..9] OF LREAL; head, i : INT; END_VAR
buf[head] := x;
head := (head + 1) MOD 10;
sum := 0.0;
peak := buf[0];
FOR i := 0 TO 9 DO
  sum := sum + buf[i];
  IF buf[i] > peak THEN peak := buf[i]; END_IF;
END_FOR;
END_FUNCTION_BLOCK
)");
  const std::string body = R"(
tasks: [{name: main, period: 10ms}]
sources: [window.st]
tags:
  - {name: x, type: LREAL, init: 1.5}
  - {name: sum, type: LREAL}
  - {name: peak, type: LREAL}
blocks:
  - {name: w, type: Window}
connections: [x -> w.x, w.sum -> sum, w.peak -> peak]
)";
  const std::string tests = temp_file("st_engine/t.yaml", yaml(R"(
cases:
  - name: a window of ten samples
    steps:
      - at: 0ms
        expect: {sum: 1.5, peak: 1.5}
      - at: 20ms
        set: {x: 4.0}
      - at: 30ms
        expect: {sum: 11.0, peak: 4.0}
      - at: 200ms
        expect: {sum: 40.0, "w.buf[3]": 4.0}
)"));
  const std::string native = temp_file("st_engine/native.yaml", yaml(("project: {name: n}\n" + body).c_str()));
  const std::string interp =
      temp_file("st_engine/interp.yaml", yaml(("project: {name: i, st_engine: interpreter}\n" + body).c_str()));
  for (const std::string& project : {native, interp}) {
    const auto r = run_scan_tests(project, tests);
    EXPECT_TRUE(r.ok()) << project << "\n" << report_text(r);
  }
  const auto n = load_project(native);
  ASSERT_LOADS(n);
  EXPECT_EQ(n.st.files, 1u);
  EXPECT_EQ(n.st.pous, 1u);
  EXPECT_TRUE(n.st.native_asked);
#if defined(__x86_64__)
  EXPECT_EQ(n.st.native_pous, 1u);
  EXPECT_EQ(n.st.register_loops, 1u);
#endif
  const auto i = load_project(interp);
  ASSERT_LOADS(i);
  EXPECT_FALSE(i.st.native_asked);
  EXPECT_EQ(i.st.pous, 1u);
  EXPECT_EQ(i.st.native_pous, 0u);
  EXPECT_EQ(i.st.register_loops, 0u);
  const std::string bad = temp_file("st_engine/bad.yaml", yaml(("project: {name: b, st_engine: jit}\n" + body).c_str()));
  const auto b = load_project(bad);
  EXPECT_THAT(errors(b), has_error(bad + ":1:31", "st_engine: native or interpreter, not 'jit'")) << joined(b);
}

// A VAR_IN_OUT is bound by the POU that calls: a PROGRAM or FB the project
// instances has no caller, so instancing one with a VAR_IN_OUT is a load
// error at the instance (before, it loaded and its first access through the
// reference crashed the runtime). The same FB called from ST, which binds
// it, is fine.
TEST(StSources, AProjectInstanceOfAPouWithVarInOutIsRefused) {
  const std::string st = temp_file("st_inout/bump.st", R"(
FUNCTION_BLOCK Bump
VAR_IN_OUT v : LREAL; END_VAR
v := v + 1.0;
END_FUNCTION_BLOCK

PROGRAM Main
VAR x : LREAL; b : Bump; END_VAR
b(v := x);
END_PROGRAM

PROGRAM Loose
VAR_IN_OUT io : LREAL; END_VAR
io := io + 1.0;
END_PROGRAM
)");
  const std::string ok = temp_file("st_inout/ok.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [bump.st]
programs: [{name: main, type: Main}]
)"));
  const auto good = load_project(ok);
  ASSERT_LOADS(good);
  const std::string bad = temp_file("st_inout/bad.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [bump.st]
programs: [{name: loose, type: Loose}]
blocks: [{name: b, type: Bump}]
)"));
  const auto r = load_project(bad);
  const auto e = errors(r);
  EXPECT_THAT(e, has_error(bad + ":3:32", "PROGRAM Loose has VAR_IN_OUT io: an instance the project makes has nothing to bind it"))
      << joined(r);
  EXPECT_THAT(e, has_error(bad + ":4:26", "FUNCTION_BLOCK Bump has VAR_IN_OUT v: an instance the project makes has nothing to bind it"))
      << joined(r);
}

TEST(StSources, ErrorsOfEveryStageAtTheirPlaceInOneLoad) {
  const std::string st = temp_file("st_err/bad.st", yaml(R"(
PROGRAM Main
VAR_EXTERNAL speed : INT; missing : BOOL; END_VAR
VAR x : DINT; END_VAR
x := speed + 1;
END_PROGRAM
FUNCTION_BLOCK TON
VAR_INPUT a : BOOL; END_VAR
END_FUNCTION_BLOCK
)"));
  const std::string project = temp_file("st_err/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [bad.st, nowhere.st]
tags:
  - {name: speed, type: LREAL}
  - {name: missed, type: BOOL}
programs:
  - {name: main_prog, type: Maim, task: main}
)"));
  const auto r = load_project(project);
  EXPECT_FALSE(r.ok());
  const auto e = errors(r);
  EXPECT_THAT(e, has_error(project + ":2:19", "sources: cannot read 'nowhere.st'")) << joined(r);
  // Missing files stop the ST stage; fix that and look at the rest.
  temp_file("st_err/nowhere.st", "");
  const auto r2 = load_project(project);
  const auto e2 = errors(r2);
  EXPECT_THAT(e2, has_error(st + ":6:1", "'TON' is the name of a built-in function block")) << joined(r2);
  EXPECT_THAT(e2, has_error(project + ":7:29", "no PROGRAM 'Maim' in the sources")) << joined(r2);
  // Without the checker's error, the program types exist and the misspelt one gets its suggestion.
  temp_file("st_err/bad.st", yaml(R"(
PROGRAM Main
END_PROGRAM
)"));
  temp_file("st_err/nowhere.st", "");
  const auto r3 = load_project(project);
  EXPECT_THAT(errors(r3), has_error(project + ":7:29", "no PROGRAM 'Maim' in the sources (did you mean Main?)"))
      << joined(r3);
}

TEST(StSources, VarExternalMustNameATagOfTheSameType) {
  const std::string st = temp_file("st_ext/e.st", yaml(R"(
PROGRAM Main
VAR_EXTERNAL
  speed : INT;
  misssed : BOOL;
  ok : LREAL;
END_VAR
ok := ok + 1.0;
END_PROGRAM
)"));
  const std::string project = temp_file("st_ext/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [e.st]
tags:
  - {name: speed, type: LREAL}
  - {name: missed, type: BOOL}
  - {name: ok, type: LREAL}
programs: [{name: m, type: Main}]
)"));
  const auto r = load_project(project);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), has_error(st + ":3:3", "VAR_EXTERNAL speed : INT of Main does not match tag speed : LREAL"))
      << joined(r);
  EXPECT_THAT(errors(r), has_error(st + ":4:3", "no tag 'misssed' in the project (did you mean missed?)")) << joined(r);
}

TEST(StSources, SyntaxAndTypeErrorsOfTheSourcesAreLoadErrors) {
  const std::string st = temp_file("st_syn/s.st", yaml(R"(
PROGRAM Main
VAR x : INT; y : LREAL; END_VAR
x := y;
IF x THEN x := 1 END_IF;
END_PROGRAM
)"));
  const std::string project = temp_file("st_syn/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: s.st
programs: [{name: m, type: Main}]
)"));
  const auto r = load_project(project);
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), has_error(st + ":4:18", "expected ';'")) << joined(r);
}

TEST(StSources, ARunawayLoopIsStoppedEachScanAndTheTaskGoesOn) {
  temp_file("st_loop/l.st", yaml(R"(
PROGRAM Runaway
VAR_EXTERNAL n : DINT; after : BOOL; END_VAR
n := 0;
WHILE TRUE DO
  n := n + 1;
END_WHILE;
after := TRUE;
END_PROGRAM
PROGRAM Ticks
VAR_EXTERNAL ticks : DINT; END_VAR
ticks := ticks + 1;
END_PROGRAM
)"));
  const std::string project = temp_file("st_loop/p.yaml", yaml(R"(
tasks:
  - {name: main, period: 10ms, watchdog: {time: 5ms}}
  - {name: other, period: 10ms}
sources: [l.st]
tags:
  - {name: n, type: DINT}
  - {name: after, type: BOOL}
  - {name: ticks, type: DINT}
programs:
  - {name: runaway, type: Runaway, task: main}
  - {name: counter, type: Ticks, task: other}
)"));
  const std::string tests = temp_file("st_loop/t.yaml", yaml(R"(
cases:
  - name: the loop is stopped after its budget, on every scan alike
    steps:
      - at: 0ms
        expect: {n: 500001, after: FALSE, ticks: 1}
      - at: 100ms
        expect: {n: 500001, after: FALSE, ticks: 11}
)"));
  const auto r = run_scan_tests(project, tests);
  EXPECT_TRUE(r.ok()) << report_text(r);
}

// A variable of an ST instance is the source of a connection, as an output
// pin is: into a tag (and with it the Modbus map, trends, the HMI, retain of
// the tag) or into another block's input. Writes from outside reach ST
// through tags (VAR_EXTERNAL), so a variable is never a connection's end.
TEST(StSources, AProgramInstancesTransientSyncWithItsParameterAsTheGraphDoes) {
  // The same block with n := 4 in ST and in the graph, fed the same
  // references: their positions differ by exactly 0 at every step, and all
  // four axes arrive together.
  temp_file("st_sync/axes.st", R"(
PROGRAM Axes
VAR_EXTERNAL go : BOOL; refs : ARRAY[1..4] OF LREAL; END_VAR
VAR
  sync : TRANSIENT_SYNC := (n := 4);
  r : ARRAY[1..4] OF LREAL;
  lim : ARRAY[1..4] OF LREAL := [4(1.0)]; nlim : ARRAY[1..4] OF LREAL := [4(-1.0)];
  acc : ARRAY[1..4] OF LREAL := [4(2.0)]; nacc : ARRAY[1..4] OF LREAL := [4(-2.0)];
  targets : ARRAY[1..4] OF LREAL := [0.5, -1.0, 1.5, 0.25];
END_VAR
IF go THEN r := targets; END_IF;
refs := r;
sync(r := r, v_min := nlim, v_max := lim, a_min := nacc, a_max := acc);
END_PROGRAM
)");
  const std::string project = temp_file("st_sync/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [axes.st]
tags:
  - {name: go, type: BOOL, hmi: readwrite}
  - {name: refs, type: "ARRAY[1..4] OF LREAL"}
  - {name: d2, type: LREAL}
  - {name: d3, type: LREAL}
programs:
  - {name: prog, type: Axes, task: main}
blocks:
  - name: ts
    type: TRANSIENT_SYNC
    params: {n: 4}
    inputs: {r_dot: 0, v_min: -1, v_max: 1, a_min: -2, a_max: 2}
  - {name: diff2, type: SUB}
  - {name: diff3, type: SUB}
connections:
  - refs -> ts.r
  - prog.sync.x[2] -> diff2.IN1
  - ts.x[2] -> diff2.IN2
  - diff2.OUT -> d2
  - prog.sync.x[3] -> diff3.IN1
  - ts.x[3] -> diff3.IN2
  - diff3.OUT -> d3
)"));
  const std::string tests = temp_file("st_sync/t.yaml", yaml(R"(
cases:
  - name: ST and the graph agree, and the axes arrive together
    steps:
      - at: 0ms
        expect: {"prog.sync.x[2]": 0.0, d2: 0.0, prog.sync.synchronized: TRUE}
      - at: 10ms
        set: {go: TRUE}
        expect: {prog.sync.synchronized: FALSE}
      - at: 300ms
        expect: {d2: 0.0, d3: 0.0}
      - at: 900ms
        expect: {d2: 0.0, d3: 0.0, prog.sync.synchronized: FALSE}
      - at: 3000ms
        expect: {"prog.sync.x[2]": -1.0, "prog.sync.x[3]": 1.5, d2: 0.0, d3: 0.0, prog.sync.synchronized: TRUE,
                 prog.sync.spread: 0, prog.sync.windows: 1}
)"));
  const auto r = run_scan_tests(project, tests);
  EXPECT_TRUE(r.ok()) << report_text(r);
  auto l = load_project(project);
  ASSERT_LOADS(l);
  std::string why;
  EXPECT_FALSE(l.program->resolve("prog.sync.x[5]", &why));
  EXPECT_EQ(why, "prog.sync.x[5]: 'sync.x[5]': index 5 is outside 1..4");
}

TEST(StSources, InstanceVariablesFeedTagsAndPinsThroughConnections) {
  temp_file("st_conn/c.st", yaml(R"(
PROGRAM Cell
VAR_EXTERNAL run : BOOL; END_VAR
VAR scans : DINT; t : TON; hist : ARRAY[1..3] OF LREAL; s : STRUCT_HOLD; END_VAR
scans := scans + 1;
t(IN := run, PT := T#30ms);
hist[3] := hist[2]; hist[2] := hist[1]; hist[1] := DINT_TO_LREAL(scans);
s.level := hist[1] * 0.5;
END_PROGRAM
TYPE STRUCT_HOLD : STRUCT level : LREAL; END_STRUCT; END_TYPE
)"));
  const std::string project = temp_file("st_conn/p.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}]
sources: [c.st]
tags:
  - {name: run, type: BOOL, hmi: readwrite}
  - {name: scans_shown, type: DINT, hmi: read, modbus: {table: input_register, address: 100}, trend: true}
  - {name: elapsed, type: TIME, hmi: read}
  - {name: second, type: LREAL, hmi: read, trend: {rate: 50ms}}
  - {name: doubled, type: LREAL, hmi: read}
programs:
  - {name: cell, type: Cell, task: main}
blocks:
  - {name: twice, type: MUL, inputs: {IN2: 2.0}}
connections:
  - cell.scans -> scans_shown
  - cell.t.ET -> elapsed
  - {from: "cell.hist[2]", to: second}
  - cell.s.level -> twice.IN1
  - twice.OUT -> doubled
)"));
  const std::string tests = temp_file("st_conn/t.yaml", yaml(R"(
cases:
  - name: the tags follow the variables, scan by scan
    steps:
      - at: 0ms
        expect: {scans_shown: 1, elapsed: 0ms, second: 0.0, doubled: 1.0}
      - at: 20ms
        set: {run: TRUE}
        expect: {scans_shown: 3, second: 2.0, doubled: 3.0}
      - at: 60ms
        expect: {scans_shown: 7, elapsed: 30ms, "cell.hist[2]": 6.0, second: 6.0, doubled: 7.0}
)"));
  const auto r = run_scan_tests(project, tests);
  EXPECT_TRUE(r.ok()) << report_text(r);
  auto l = load_project(project);
  ASSERT_LOADS(l);
  const Tag* shown = l.program->find_tag("scans_shown");
  ASSERT_TRUE(shown);
  EXPECT_EQ(shown->writer, "block cell.scans");
  EXPECT_TRUE(shown->written_every_scan);
  // The program runs before the block its variable feeds.
  const auto& blocks = l.program->tasks[0]->blocks;
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].name, "cell");
  EXPECT_EQ(blocks[1].name, "twice");

  // Each wrong end at its place, with the reason.
  const std::string bad = temp_file("st_conn/bad.yaml", yaml(R"(
tasks: [{name: main, period: 10ms}, {name: slow, period: 50ms}]
sources: [c.st]
tags:
  - {name: run, type: BOOL}
  - {name: x, type: DINT}
  - {name: y, type: LREAL}
programs:
  - {name: cell, type: Cell, task: main}
blocks:
  - {name: other, type: MUL, task: slow, inputs: {IN2: 1.0}}
connections:
  - cell.scanz -> x
  - x -> cell.scans
  - cell.hist -> y
  - cell.scans -> y
  - cell.s.level -> other.IN1
)"));
  const auto e = load_project(bad);
  EXPECT_FALSE(e.ok());
  EXPECT_THAT(errors(e), has_error(bad + ":12:5", "Cell has no variable 'scanz' (did you mean scans?)")) << joined(e);
  EXPECT_THAT(errors(e), has_error(bad + ":13:10", "cell.scans is a variable of ST instance cell: a connection ends at "
                                                   "an input or a tag (the program reads a tag through VAR_EXTERNAL)"))
      << joined(e);
  EXPECT_THAT(errors(e), has_error(bad + ":14:5", "it is a ARRAY[1..3] OF LREAL: address one of its elements")) << joined(e);
  EXPECT_THAT(errors(e), has_error(bad + ":15:5", "type mismatch: cell.scans is DINT, y is LREAL")) << joined(e);
  EXPECT_THAT(errors(e), has_error(bad + ":16:5", "blocks in different tasks exchange data through a tag")) << joined(e);
}

}  // namespace st_sources
}  // namespace syncplc::loadertest
