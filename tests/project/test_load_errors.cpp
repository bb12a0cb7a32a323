// One test per kind of load error: each asserts the exact file:line:col and
// the gist of the message. Line numbers are written at the end of the YAML
// lines (# n) where it helps.
#include "tests/project/loader_test_util.hpp"

#include "runtime/core/pin_decl.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;
using ::testing::SizeIs;

// --- the file itself ----------------------------------------------------------------

TEST(LoadErrors, YamlSyntaxError) {
  auto r = load(R"(
tasks:
  - {name: main, period: 1ms
tags: []
)");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.program, nullptr);
  EXPECT_THAT(errors(r), ElementsAre("p.yaml:3:5: YAML syntax error: did not find expected ',' or '}' (while parsing a flow "
                                     "mapping that starts at line 2, column 5)"));
}

TEST(LoadErrors, YamlSyntaxErrorBadIndentation) {
  EXPECT_THAT(errors(R"(
tasks:
  - name: main
   period: 1ms
)"),
              ElementsAre(::testing::StartsWith("p.yaml:3:4: YAML syntax error")));
}

TEST(LoadErrors, NotAMap) {
  EXPECT_THAT(errors("- a\n- b\n"), ElementsAre(::testing::StartsWith("p.yaml:1:1: a project file is a map")));
  EXPECT_THAT(errors(""), ElementsAre(::testing::StartsWith("p.yaml:1:1: a project file is a map")));
}

TEST(LoadErrors, MissingFile) {
  auto r = load_project("/nonexistent/dir/project.yaml");
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), ElementsAre("/nonexistent/dir/project.yaml:0:0: cannot open file"));
}

TEST(LoadErrors, UnknownTopLevelKey) {
  // The place is the key's value.
  EXPECT_THAT(errors(R"(
tasks:
  - {name: main, period: 1ms}
tag:
  - {name: x, type: BOOL}
)"),
              ElementsAre("p.yaml:4:3: unknown top-level key 'tag' (project, include, tasks, tags, blocks, programs, sources, "
                          "connections, drivers, traces, watch, metrics, modbus, store)"));
}

TEST(LoadErrors, DuplicateKeyInAMap) {
  EXPECT_THAT(errors(R"(
tasks:
  - name: main
    period: 1ms
    period: 2ms
tags: []
tags: []
)"),
              ElementsAre("p.yaml:4:5: duplicate key 'period'", "p.yaml:6:1: duplicate key 'tags'"));
}

TEST(LoadErrors, NoTasks) {
  EXPECT_THAT(errors("tags: []\n"), ElementsAre("p.yaml:1:1: the project has no tasks"));
}

TEST(LoadErrors, UnknownKeysInSections) {
  auto e = errors(R"(
project: {name: p, owner: me}
tasks:
  - {name: main, period: 1ms, colour: red, watchdog: {time: 1ms, mood: calm}}
tags:
  - {name: x, type: BOOL, colour: red}
blocks:
  - {name: n, type: NOT, colour: red, inputs: {IN: TRUE}}
)");
  EXPECT_THAT(e, SizeIs(5));
  EXPECT_THAT(e, has_error("p.yaml:1:27", "unknown key 'owner' in project"));
  EXPECT_THAT(e, has_error("p.yaml:3:39", "unknown key 'colour' in a task"));
  EXPECT_THAT(e, has_error("p.yaml:3:72", "unknown key 'mood' in watchdog"));
  EXPECT_THAT(e, has_error("p.yaml:5:35", "unknown key 'colour' in a tag"));
  EXPECT_THAT(e, has_error("p.yaml:7:34", "unknown key 'colour' in a block instance"));
}

// --- engineering limits (min, max) ----------------------------------------------------

TEST(LoadErrors, EngineeringLimitsAreValuesOfANumericTagInItsUnitAndHoldItsOwnValues) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: LREAL, min: 10, max: 5}
  - {name: b, type: BOOL, max: 1}
  - {name: c, type: INT, min: lots}
  - {name: d, type: LREAL, unit: m/s, max: 100, init: 101}
  - {name: e, type: INT, min: 0, safe: -1}
)");
  EXPECT_THAT(e, SizeIs(5));
  EXPECT_THAT(e, has_error("p.yaml:3:33", "min 10 is above max 5 of a"));
  EXPECT_THAT(e, has_error("p.yaml:4:32", "min and max are for numeric tags; b is BOOL"));
  EXPECT_THAT(e, has_error("p.yaml:5:31", "min: 'lots' is not an integer"));
  EXPECT_THAT(e, has_error("p.yaml:6:55", "init: 101 m/s is above d's max 100 m/s (its engineering limit)"));
  EXPECT_THAT(e, has_error("p.yaml:7:40", "safe value: -1 is below e's min 0 (its engineering limit)"));
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, unit: m/s, min: "-3600 m/h", max: 2, init: 1}
)");
  ASSERT_TRUE(r.ok()) << ::testing::PrintToString(errors(r));
  const Tag* t = r.program->find_tag("speed");
  ASSERT_TRUE(t && t->min && t->max);
  EXPECT_DOUBLE_EQ(*t->min, -1.0) << "in the tag's unit";
  EXPECT_DOUBLE_EQ(*t->max, 2.0);
}

// --- duplicate names ------------------------------------------------------------------

TEST(LoadErrors, DuplicateTask) {
  EXPECT_THAT(errors(R"(
tasks:
  - {name: main, period: 1ms}
  - {name: main, period: 2ms}
)"),
              ElementsAre("p.yaml:3:12: duplicate task 'main'"));
}

TEST(LoadErrors, DuplicateTag) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: x, type: BOOL}
  - {name: x, type: INT}
)"),
              ElementsAre("p.yaml:4:12: duplicate name 'x' (first defined at p.yaml:3:12)"));
}

TEST(LoadErrors, DuplicateInstance) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: t, type: TON, inputs: {IN: TRUE}}
  - {name: t, type: TOF, inputs: {IN: TRUE}}
)"),
              ElementsAre("p.yaml:4:12: duplicate name 't' (first defined at p.yaml:3:12)"));
}

TEST(LoadErrors, TagAndInstanceShareOneNamespace) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: lamp, type: BOOL}
blocks:
  - {name: lamp, type: NOT, inputs: {IN: TRUE}}
drivers:
  - {name: lamp, type: memory, channels: []}
)"),
              ElementsAre("p.yaml:5:12: duplicate name 'lamp' (first defined at p.yaml:3:12)",
                          "p.yaml:7:12: duplicate name 'lamp' (first defined at p.yaml:3:12)"));
}

TEST(LoadErrors, BadNames) {
  auto e = errors(R"(
tasks: [{name: 2fast, period: 1ms}, {period: 1ms}]
tags:
  - {name: my-tag, type: BOOL}
  - {type: BOOL}
)");
  EXPECT_THAT(e, has_error("p.yaml:1:16", "task name '2fast' is not an identifier"));
  EXPECT_THAT(e, has_error("p.yaml:1:37", "task without a name"));
  EXPECT_THAT(e, has_error("p.yaml:3:12", "tag name 'my-tag' is not an identifier"));
  EXPECT_THAT(e, has_error("p.yaml:4:5", "tag without a name"));
}

// --- tasks ----------------------------------------------------------------------------------

TEST(LoadErrors, UnknownTaskReference) {
  auto e = errors(R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: x, type: BOOL, task: medium}
blocks:
  - {name: n, type: NOT, task: fats, inputs: {IN: TRUE}}
  - {name: m, type: NOT, inputs: {IN: TRUE}}
drivers:
  - {name: io, type: memory, task: sloww, channels: []}
)");
  EXPECT_THAT(e, SizeIs(4));
  EXPECT_THAT(e, has_error("p.yaml:5:33", "unknown task 'medium'"));
  EXPECT_THAT(e, has_error("p.yaml:7:32", "unknown task 'fats'"));
  EXPECT_THAT(e, has_error("p.yaml:8:5", "block instance m has no task"));  // two tasks: task: is required
  EXPECT_THAT(e, has_error("p.yaml:10:36", "unknown task 'sloww'"));
}

TEST(LoadErrors, PeriodOutOfRange) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 50us}
  - {name: b, period: 11s}
  - {name: c, period: 100us}
  - {name: d, period: 10s}
  - {name: e}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:23: period 50us is outside 100us .. 10s",
                             "p.yaml:3:23: period 11s is outside 100us .. 10s", "p.yaml:6:5: task e has no period"));
}

TEST(LoadErrors, BadlyWrittenDurations) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 1 ms x}
  - {name: b, period: 5q}
  - {name: c, period: 1ms2s}
  - {name: d, period: ms}
  - {name: e, period: 10}
  - {name: f, period: 1ms, phase: 1.5.2us}
)");
  EXPECT_THAT(e, SizeIs(6));
  EXPECT_THAT(e, has_error("p.yaml:2:23", "period: '1 ms x' is not a duration"));
  EXPECT_THAT(e, has_error("p.yaml:3:23", "period: '5q' is not a duration (unknown unit 'q'"));
  EXPECT_THAT(e, has_error("p.yaml:4:23", "units must go from largest to smallest"));
  EXPECT_THAT(e, has_error("p.yaml:5:23", "missing number"));
  EXPECT_THAT(e, has_error("p.yaml:6:23", "missing unit after 10"));
  EXPECT_THAT(e, has_error("p.yaml:7:35", "phase: '1.5.2us' is not a duration (bad number '1.5.2'"));
}

TEST(LoadErrors, PhaseNotShorterThanPeriod) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 1ms, phase: 1ms}
  - {name: b, period: 1ms, phase: 2ms}
  - {name: c, period: 1ms, phase: 999us}
  - {name: d, period: 1ms, phase: -1us}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:35: phase must be shorter than the period",
                             "p.yaml:3:35: phase must be shorter than the period",
                             "p.yaml:5:35: phase must not be negative"));
}

TEST(LoadErrors, NoPhaseErrorAfterAnUnreadablePeriod) {
  // The period could not be read: the phase is not compared with a default.
  EXPECT_THAT(errors(R"(
tasks:
  - {name: a, period: 20ms x, phase: 5ms}
)"),
              ElementsAre(::testing::StartsWith("p.yaml:2:23: period: '20ms x' is not a duration")));
}

TEST(LoadErrors, PriorityOutOfRange) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 1ms, priority: 0}
  - {name: b, period: 1ms, priority: 100}
  - {name: c, period: 1ms, priority: high}
  - {name: d, period: 1ms, priority: 1}
  - {name: e, period: 1ms, priority: 99}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:38: priority 0 is outside 1..99 (SCHED_FIFO; higher runs first)",
                             "p.yaml:3:38: priority 100 is outside 1..99 (SCHED_FIFO; higher runs first)",
                             "p.yaml:4:38: priority: 'high' is not an integer"));
}

TEST(LoadErrors, BadWatchdog) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 1ms, watchdog: {time: 1ms, action: explode}}
  - {name: b, period: 1ms, watchdog: {time: 1ms, sensitivity: 0}}
  - {name: c, period: 1ms, watchdog: {time: 1ms, sensitivity: 1001}}
  - {name: d, period: 1ms, watchdog: {action: stop}}
  - {name: e, period: 1ms, watchdog: {time: 0ms}}
  - {name: f, period: 1ms, watchdog: 1ms}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:58: watchdog action must be log, stop or safe_stop, not 'explode'",
                             "p.yaml:3:63: sensitivity must be an integer 1..1000",
                             "p.yaml:4:63: sensitivity must be an integer 1..1000",
                             "p.yaml:5:38: watchdog needs a time",
                             "p.yaml:6:45: watchdog time must be positive",
                             "p.yaml:7:38: watchdog: expected a map {time, sensitivity, action}"));
}

TEST(LoadErrors, OtherTaskSettings) {
  auto e = errors(R"(
tasks:
  - {name: a, period: 1ms, missed_cycles: never, cpu: -1, write_queue: 8}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:43: missed_cycles must be 'skip' or 'immediate', not 'never'",
                             "p.yaml:2:55: cpu: a CPU number 0..1023", "p.yaml:2:72: write_queue: 16..1000000 entries"));
}

TEST(LoadErrors, AWriteQueueTooSmallForOneModbusWrite) {
  // 20 writable registers of task a: one FC 16 can queue 20 values, its queue holds 16.
  // Task b's 200 coils, read only, and c's default queue (which grows) are no error.
  auto e = errors(R"(
tasks:
  - {name: a, period: 1ms, write_queue: 16}
  - {name: b, period: 1ms, write_queue: 16}
  - {name: c, period: 1ms}
tags:
  - {name: sp, type: "ARRAY[0..19] OF INT", address: "%MW0", hmi: readwrite, task: a}
  - {name: lamps, type: "ARRAY[0..199] OF BOOL", address: "%QX0.0", hmi: read, task: b}
  - {name: valves, type: "ARRAY[0..1999] OF BOOL", address: "%QX100.0", hmi: readwrite, task: c}
blocks:
  - {name: m, type: NOPE, task: a}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:2:41: write_queue 16 of task a cannot hold one Modbus write to its tags: "
                             "a request can queue 20 values to it at once",
                             "p.yaml:10:21: unknown block type 'NOPE' (see `syncplc blocks`)"))
      << "reported in the same load as the other errors";
}

// --- blocks -------------------------------------------------------------------------------

TEST(LoadErrors, UnknownBlockType) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: t1, type: TONX}
  - {name: t2}
)"),
              ElementsAre("p.yaml:3:22: unknown block type 'TONX' (see `syncplc blocks`)",
                          "p.yaml:4:5: block instance t2 has no type"));
}

TEST(LoadErrors, UnknownPinInAConnection) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}]
blocks: [{name: t1, type: TON, inputs: {PT: 1s}}]
connections:
  - go -> t1.IN
  - t1.QQ -> go
  - go -> t1.XX
)"),
              ElementsAre("p.yaml:6:5: block t1 (TON) has no pin 'QQ' (IN, PT, Q, ET, ENO)",
                          "p.yaml:7:11: block t1 (TON) has no pin 'XX' (IN, PT, Q, ET, ENO)"));
}

TEST(LoadErrors, UnknownPinInInputs) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: t1, type: TON, inputs: {IN: TRUE, XX: 1s, Q: TRUE}}
)"),
              // The valid pins are listed, as for the same mistake in a connection.
              ElementsAre("p.yaml:3:50: block t1 (TON) has no pin 'XX' (IN, PT, Q, ET, ENO)",
                          "p.yaml:3:57: TON.Q is an output: it takes no constant"));
}

TEST(LoadErrors, UnknownInstanceOrTagInAConnection) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}]
blocks: [{name: n, type: NOT}]
drivers: [{name: io, type: memory, channels: [{name: b, dir: in, type: BOOL}]}]
connections:
  - ghost.OUT -> n.IN
  - n.OUT -> nowhere
  - io.b -> go
)"),
              // n.IN is wired, to a source that is wrong: no "must be connected" on top.
              ElementsAre("p.yaml:6:5: unknown block instance 'ghost'", "p.yaml:7:14: unknown tag or instance.pin 'nowhere'",
                          "p.yaml:8:5: 'io' is not a block instance (connect drivers with bind:)"));
}

TEST(LoadErrors, UnknownParameter) {
  LoadOptions o;
  o.blocks = &param_blocks();
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: t, type: TON, inputs: {IN: TRUE}, params: {P: 1}}
  - {name: g, type: GAIN, inputs: {IN: 1}, params: {K: 2, Q: 3}}
  - {name: k, type: NEED}
)",
                  o);
  EXPECT_THAT(e, ElementsAre("p.yaml:3:58: TON has no parameter 'P' (it has none)",
                             "p.yaml:4:62: GAIN has no parameter 'Q' (K, N)",
                             "p.yaml:5:5: block instance k needs parameter P"));
}

TEST(LoadErrors, ParameterOutOfRangeAndBadUnit) {
  LoadOptions o;
  o.blocks = &param_blocks();
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: g1, type: GAIN, inputs: {IN: 1}, params: {K: 200}}
  - {name: g2, type: GAIN, inputs: {IN: 1}, params: {K: 3 kg}}
  - {name: g3, type: GAIN, inputs: {IN: 1}, params: {N: 1.5}}
  - {name: g4, type: GAIN, inputs: {IN: 1}, params: {K: 6000 mm/min}}
)",
                  o);
  EXPECT_THAT(e, ElementsAre("p.yaml:3:57: g1.K = 200 is outside its range 0 .. 100 m/s",
                             "p.yaml:4:57: g2.K: unit 'kg' is not compatible with 'm/s'",
                             "p.yaml:5:57: g3.N: '1.5' is not an integer"));
}

TEST(LoadErrors, ConnectionWithoutArrow) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}]
blocks: [{name: n, type: NOT, inputs: {IN: TRUE}}]
connections:
  - n.OUT go
  - n.OUT => go
  - {from: n.OUT}
)"),
              ElementsAre("p.yaml:5:5: a connection is written 'source.pin -> target.pin'",
                          "p.yaml:6:5: a connection is written 'source.pin -> target.pin'",
                          "p.yaml:7:5: a connection is written 'source.pin -> target.pin' or {from: , to: }"));
}

TEST(LoadErrors, ConnectionFromAnInputOrToAnOutput) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: a, type: NOT, inputs: {IN: TRUE}}
  - {name: b, type: NOT, inputs: {IN: TRUE}}
connections:
  - a.IN -> b.IN
  - a.OUT -> b.OUT
)"),
              ElementsAre("p.yaml:6:5: a.IN is an input: a connection starts at an output or a tag",
                          "p.yaml:7:14: b.OUT is an output: a connection ends at an input or a tag"));
}

TEST(LoadErrors, TypeMismatchOnAConnection) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: go, type: BOOL}
  - {name: n, type: INT}
  - {name: speed, type: LREAL}
blocks:
  - {name: t, type: TON, inputs: {IN: TRUE}}
  - {name: add, type: ADD, datatype: DINT}
connections:
  - go -> t.PT
  - t.ET -> n
  - n -> add.IN1
  - speed -> add.IN2
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:10:5: type mismatch: go is BOOL, t.PT is TIME",
                             "p.yaml:11:5: type mismatch: t.ET is TIME, n is INT",
                             "p.yaml:12:5: type mismatch: n is INT, add.IN1 is DINT",
                             "p.yaml:13:5: type mismatch: speed is LREAL, add.IN2 is DINT"));
}

TEST(LoadErrors, GenericInstanceWithImpossibleDatatype) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: c, type: CTU, datatype: REAL, inputs: {PV: 3}}
  - {name: n, type: NOT, datatype: TIME, inputs: {IN: 1}}
  - {name: a, type: ADD, datatype: FLOAT, inputs: {IN1: 1, IN2: 2}}
  - {name: t, type: TON, datatype: INT, inputs: {IN: TRUE}}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:3:36: CTU pin PV is ANY_INT: REAL does not belong to it",
                             "p.yaml:4:36: NOT pin IN is ANY_BIT: TIME does not belong to it",
                             "p.yaml:5:36: unknown IEC type 'FLOAT'",
                             "p.yaml:6:36: TON is not generic: it takes no datatype"));
}

TEST(LoadErrors, GenericTypeConnectedOutsideItsClass) {
  // NOT takes ANY_BIT: an INT tag cannot fix its type, so it takes its default
  // (BOOL) and the connection is a mismatch.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: n, type: INT}]
blocks: [{name: inv, type: NOT}]
connections:
  - n -> inv.IN
)"),
              ElementsAre("p.yaml:5:5: type mismatch: n is INT, inv.IN is BOOL"));
}

// --- values ---------------------------------------------------------------------------------

TEST(LoadErrors, OutOfRangeLiterals) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: INT, init: 40000}
  - {name: b, type: USINT, init: -1}
  - {name: c, type: SINT, init: 16#80}
  - {name: d, type: REAL, init: 1e39}
  - {name: e, type: INT, init: -32768}
  - {name: f, type: BYTE, init: 256}
  - {name: g, type: REAL, init: 3.4028236e38}
  - {name: h, type: REAL, unit: mm, init: 4e35 m}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:3:32: init of a: value 40000 is out of range for INT (-32768 .. 32767)",
                             "p.yaml:4:34: init of b: value -1 is out of range for USINT (unsigned)",
                             "p.yaml:5:33: init of c: value 16#80 is out of range for SINT (-128 .. 127)",
                             "p.yaml:6:33: init of d: value 1e39 is out of range for REAL",
                             "p.yaml:8:33: init of f: value 256 is out of range for BYTE (0 .. 255)",
                             "p.yaml:9:33: init of g: value 3.4028236e38 is out of range for REAL",
                             "p.yaml:10:43: init of h: value 4e35 m is out of range for REAL"));  // 4e38 mm
}

TEST(LoadErrors, BadlyWrittenValues) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: BOOL, init: maybe}
  - {name: b, type: INT, init: 12abc}
  - {name: c, type: TIME, init: 5 parsecs}
  - {name: d, type: LREAL, init: fast}
  - {name: e, type: INT, init: DINT#5}
  - {name: f, type: BOOL, safe: [TRUE, FALSE]}
  - {name: g, type: INT, init: {x: 1}}
  - {name: h, type: BOOL, retain: sometimes, hmi: write}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:3:33: init of a: 'maybe' is not a BOOL (TRUE or FALSE)",
                             "p.yaml:4:32: init of b: '12abc' is not an integer",
                             "p.yaml:5:33: init of c: '5 parsecs' is not a duration (no space may separate 5 from its unit: 5parsecs; "
                             "write e.g. 1ms, 250us, 0.5s, T#1m30s)",
                             "p.yaml:6:34: init of d: 'fast' is not a number",
                             "p.yaml:7:32: init of e: literal DINT#5 is DINT, expected INT",
                             "p.yaml:8:33: safe value of f: 2 values for 1 elements",
                             "p.yaml:9:32: init of g: expected a value or a list of values",
                             "p.yaml:10:35: retain: 'sometimes' is not a BOOL (TRUE or FALSE)",
                             "p.yaml:10:51: hmi must be none, read or readwrite, not 'write'"));
}

TEST(LoadErrors, BadTypes) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: FLOAT}
  - {name: b, type: "ARRAY[4..1] OF INT"}
  - {name: c, type: "ARRAY[0..3] OF FOO"}
  - {name: d, type: "ARRAY[0..3]"}
  - {name: e, type: "ARRAY[0..70000] OF BOOL"}
  - {name: f}
)");
  EXPECT_THAT(e, ElementsAre(
                     "p.yaml:3:21: unknown IEC type 'FLOAT' (BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, ULINT, "
                     "BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME or ARRAY[a..b] OF type)",
                     "p.yaml:4:21: array bounds of 'ARRAY[4..1] OF INT' must give 1..65536 elements",
                     "p.yaml:5:21: unknown element type in 'ARRAY[0..3] OF FOO'",
                     "p.yaml:6:21: bad array type 'ARRAY[0..3]' (write ARRAY[0..3] OF LREAL)",
                     "p.yaml:7:21: array bounds of 'ARRAY[0..70000] OF BOOL' must give 1..65536 elements",
                     "p.yaml:8:5: tag f has no type"));
}

TEST(LoadErrors, UnitErrors) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: v, type: LREAL, unit: m/s, init: 3 kg}
  - {name: w, type: LREAL, unit: furlong/fortnight}
  - {name: x, type: LREAL, unit: m/s, init: 3 parsec/s}
  - {name: y, type: LREAL, init: 2 m}
  - {name: z, type: LREAL, unit: m/s, safe: 1 rad/s}
  - {name: n, type: INT, unit: m, init: 5 mm}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:3:45: init of v: unit 'kg' is not compatible with 'm/s'",
                             "p.yaml:4:34: bad unit 'furlong/fortnight': unknown unit 'furlong'",
                             "p.yaml:5:45: init of x: bad unit 'parsec/s': unknown unit 'parsec'",
                             "p.yaml:6:34: init of y: '2 m' has a unit but the value is dimensionless",
                             "p.yaml:7:45: safe value of z: unit 'rad/s' is not compatible with 'm/s'",
                             "p.yaml:8:41: init of n: '5 mm' is not an integer"));
}

// --- direct addresses --------------------------------------------------------------------

TEST(LoadErrors, OverlappingDirectAddresses) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: m1, type: INT, address: "%MW2"}
  - {name: m2, type: DINT, address: "%MD1"}
  - {name: i1, type: BOOL, address: "%IX0.3"}
  - {name: i2, type: BYTE, address: "%IB0"}
  - {name: q1, type: BOOL, address: "%QX1.1"}
  - {name: q2, type: BOOL, address: "%QX1.1"}
  - {name: q3, type: BOOL, address: "%QX1.2"}
  - {name: arr, type: "ARRAY[0..3] OF WORD", address: "%MW10"}
  - {name: m3, type: WORD, address: "%MW13"}
  - {name: m4, type: WORD, address: "%MW14"}
  - {name: o1, type: INT, address: "%IW2"}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:4:37: address %MD1 of m2 overlaps %MW2 of m1 (defined at p.yaml:3:5)",
                             "p.yaml:6:37: address %IB0 of i2 overlaps %IX0.3 of i1 (defined at p.yaml:5:5)",
                             "p.yaml:8:37: address %QX1.1 of q2 overlaps %QX1.1 of q1 (defined at p.yaml:7:5)",
                             "p.yaml:11:37: address %MW13 of m3 overlaps %MW10 of arr (defined at p.yaml:10:5)"));
}

TEST(LoadErrors, AddressTypeMismatch) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: BOOL, address: "%IW0"}
  - {name: b, type: INT, address: "%QX0.0"}
  - {name: c, type: LREAL, address: "%MD4"}
  - {name: d, type: INT, address: "%XW3"}
  - {name: e, type: BOOL, address: "%IX0.9"}
  - {name: f, type: BOOL, address: "IX0.0"}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:3:36: a BOOL cannot sit at %IW0 (16-bit address; use X)",
                             "p.yaml:4:35: a INT cannot sit at %QX0.0 (1-bit address; use W)",
                             "p.yaml:5:37: a LREAL cannot sit at %MD4 (32-bit address; use L)",
                             "p.yaml:6:35: bad direct address '%XW3': area must be I, Q or M",
                             "p.yaml:7:36: bad direct address '%IX0.9': bit must be 0..7",
                             "p.yaml:8:36: bad direct address 'IX0.0': must start with %, e.g. %IX0.0, %QW3, %MD10"));
}

// --- wiring -----------------------------------------------------------------------------------

TEST(LoadErrors, RequiredPinLeftUnconnected) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: add, type: ADD, inputs: {IN1: 1}}
  - {name: sel, type: SEL}
)"),
              ElementsAre("p.yaml:3:5: input add.IN2 must be connected or given a value in inputs:",
                          "p.yaml:4:5: input sel.G must be connected or given a value in inputs:"));
}

TEST(LoadErrors, InputWithTwoSources) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: a, type: BOOL}, {name: b, type: BOOL}]
blocks: [{name: n, type: NOT}, {name: m, type: NOT, inputs: {IN: TRUE}}]
connections:
  - a -> n.IN
  - b -> n.IN
  - a -> m.IN
)"),
              ElementsAre("p.yaml:6:10: n.IN already has a source (a -> n.IN at p.yaml:5:5)",
                          "p.yaml:7:10: m.IN is connected and also given a constant in inputs:"));
}

TEST(LoadErrors, TagWithTwoBlockWriters) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: lamp, type: BOOL}]
blocks:
  - {name: a, type: NOT, inputs: {IN: TRUE}}
  - {name: b, type: NOT, inputs: {IN: FALSE}}
connections:
  - a.OUT -> lamp
  - b.OUT -> lamp
)"),
              ElementsAre("p.yaml:8:5: tag lamp has two writers: block a.OUT and block b.OUT"));
}

TEST(LoadErrors, TagWrittenByABlockAndADriverInput) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: lamp, type: BOOL}]
blocks:
  - {name: a, type: NOT, inputs: {IN: TRUE}}
connections:
  - a.OUT -> lamp
drivers:
  - name: io
    type: memory
    channels: [{name: sensor, dir: in, type: BOOL}, {name: light, dir: out, type: BOOL}]
    bind: {sensor: lamp, light: lamp}
)"),
              ElementsAre("p.yaml:11:20: tag lamp has two writers: block a.OUT and driver io.sensor"));
}

TEST(LoadErrors, ArrayElementWriters) {
  EXPECT_THAT(errors(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 2ms}]
tags: [{name: arr, type: "ARRAY[1..3] OF BOOL"}]
blocks:
  - {name: a, type: NOT, task: fast, inputs: {IN: TRUE}}
  - {name: b, type: NOT, task: fast, inputs: {IN: TRUE}}
  - {name: c, type: NOT, task: slow, inputs: {IN: TRUE}}
connections:
  - a.OUT -> arr[1]
  - b.OUT -> arr[2]
  - b.OUT -> arr[1]
  - c.OUT -> arr[3]
)"),
              ElementsAre("p.yaml:10:5: tag element arr[1] has two writers",
                          "p.yaml:11:5: tag arr is written from two tasks (block a.OUT and block c.OUT)"));
}

TEST(LoadErrors, ExplicitTaskOfATagWrittenInAnotherTask) {
  EXPECT_THAT(errors(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 2ms}]
tags: [{name: lamp, type: BOOL, task: slow}]
blocks: [{name: a, type: NOT, task: fast, inputs: {IN: TRUE}}]
connections: [a.OUT -> lamp]
)"),
              ElementsAre("p.yaml:2:39: tag lamp is written by block a.OUT in task fast, not in task slow"));
}

TEST(LoadErrors, BlocksInDifferentTasksConnectedDirectly) {
  EXPECT_THAT(errors(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 10ms}]
blocks:
  - {name: a, type: NOT, task: fast, inputs: {IN: TRUE}}
  - {name: b, type: NOT, task: slow}
connections:
  - a.OUT -> b.IN
)"),
              ElementsAre("p.yaml:4:5: input b.IN must be connected or given a value in inputs:",
                          "p.yaml:6:5: blocks in different tasks exchange data through a tag: connect a.OUT -> a tag "
                          "-> b.IN"));
}

TEST(LoadErrors, TagToTagConnection) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: a, type: BOOL}, {name: b, type: BOOL}]
connections: [a -> b]
)"),
              ElementsAre("p.yaml:3:15: tag-to-tag connection: copy a tag through a MOVE block"));
}

TEST(LoadErrors, ElementReferences) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: arr, type: "ARRAY[1..4] OF BOOL"}, {name: b, type: BOOL}]
blocks: [{name: n, type: NOT}, {name: m, type: NOT}, {name: k, type: NOT}]
connections:
  - arr[5] -> n.IN
  - b[1] -> m.IN
  - arr[x] -> k.IN
  - arr[1 -> k.IN
  - n.OUT[1] -> arr[1]
  - arr[2x] -> k.IN
)"),
              ::testing::IsSupersetOf({"p.yaml:5:5: index 5 is outside arr[1..4]", "p.yaml:6:5: tag b is not an array",
                                       "p.yaml:7:5: bad array index in 'arr[x]'",
                                       "p.yaml:8:5: bad element reference 'arr[1'", "p.yaml:9:5: pin n.OUT is not an array",
                                       "p.yaml:10:5: bad array index in 'arr[2x]'"}));
}

TEST(LoadErrors, FeedbackLoopNamesItsInstances) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}]
blocks:
  - {name: a, type: AND}
  - {name: n, type: NOT}
  - {name: o, type: OR}
connections:
  - go -> a.IN1
  - o.OUT -> a.IN2
  - a.OUT -> n.IN
  - n.OUT -> o.IN1
  - go -> o.IN2
)");
  EXPECT_FALSE(r.ok());
  EXPECT_THAT(errors(r), ElementsAre("p.yaml:9:5: feedback loop without a one-scan delay: a -> n -> o -> a "
                                     "(break it with a UNIT_DELAY block)"));
}

TEST(LoadErrors, FeedbackLoopThroughATag) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: x, type: BOOL}]
blocks:
  - {name: a, type: NOT}
  - {name: b, type: NOT}
connections:
  - a.OUT -> x
  - x -> b.IN
  - b.OUT -> a.IN
)"),
              ElementsAre(::testing::StartsWith("p.yaml:9:5: feedback loop without a one-scan delay: a -> b -> a")));
}

TEST(LoadErrors, FeedbackLoopThroughOneArrayElement) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: arr, type: "ARRAY[0..1] OF INT"}]
blocks: [{name: add, type: ADD, inputs: {IN2: 1}}]
connections:
  - arr[1] -> add.IN1
  - add.OUT -> arr[1]
)"),
              ElementsAre("p.yaml:5:5: feedback loop without a one-scan delay: add -> add (break it with a UNIT_DELAY "
                          "block)"));
}

TEST(LoadErrors, SameLoopAcceptedWithAUnitDelay) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}]
blocks:
  - {name: a, type: AND}
  - {name: n, type: NOT}
  - {name: o, type: OR}
  - {name: d, type: UNIT_DELAY}
connections:
  - go -> a.IN1
  - d.OUT -> a.IN2
  - a.OUT -> n.IN
  - n.OUT -> o.IN1
  - go -> o.IN2
  - o.OUT -> d.IN
)");
  ASSERT_LOADS(r);
  const auto& blocks = r.program->tasks[0]->blocks;
  ASSERT_EQ(blocks.size(), 4u);
  EXPECT_EQ(blocks[0].name, "d");
  EXPECT_EQ(blocks[0].datatype, IecType::BOOL);  // inferred from o.OUT
  EXPECT_EQ(r.program->tasks[0]->unit_delays, 1u);
  EXPECT_EQ(blocks[1].name, "a");
  EXPECT_EQ(blocks[2].name, "n");
  EXPECT_EQ(blocks[3].name, "o");
}

TEST(LoadErrors, CannotInferADatatypeWithoutDefault) {
  // A generic type with no default and nothing to infer from.
  BlockRegistry reg;
  register_iec_blocks(reg);
  BlockTypeInfo t;
  t.name = "PICKY";
  t.category = "test";
  t.pins = {input("IN", TypeClass::ANY_NUM)};
  t.create = [](BlockSetup&) -> std::unique_ptr<Block> { return nullptr; };
  reg.add(std::move(t));
  LoadOptions o;
  o.blocks = &reg;
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks: [{name: p, type: PICKY}]
)",
                     o),
              ElementsAre("p.yaml:2:10: cannot infer the data type of p (PICKY): set datatype:"));
}

// --- drivers ----------------------------------------------------------------------------------

TEST(LoadErrors, Drivers) {
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: n, type: INT}, {name: b, type: BOOL}]
drivers:
  - {name: d1, type: modbus}
  - {type: memory}
  - {name: d2, type: memory}
  - {name: d3, type: memory, channels: [{name: x, dir: sideways, type: INT, length: 0}], extra: 1}
  - name: d4
    type: memory
    channels: [{name: c, dir: in, type: INT}, {name: arr, dir: out, type: INT, length: 4}]
    bind: {c: nosuch, nochan: n, arr: n}
  - name: d5
    type: memory
    channels: [{name: c, dir: in, type: INT}]
    bind: {c: b}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:4:22: unknown driver type 'modbus' (dds, memory, modbus_client, sim_ring, sim_table)", "p.yaml:5:5: driver without a name",
                             "p.yaml:6:5: memory driver needs a list 'channels'",
                             "p.yaml:7:56: dir must be 'in' or 'out', not 'sideways'",
                             "p.yaml:7:85: length must be 1..65536",
                             "p.yaml:7:97: unknown key 'extra' for a memory driver (channels, bind)",
                             "p.yaml:11:15: unknown tag 'nosuch'", "p.yaml:11:31: driver d4 has no channel 'nochan'",
                             "p.yaml:11:39: type mismatch: channel d4.arr is INT[4], tag n is INT",
                             "p.yaml:15:15: type mismatch: channel d5.c is INT, tag b is BOOL"));
}

TEST(LoadErrors, DriverChannelsAndTheirTagsMustMeanOneUnit) {
  // A channel copies its value as it is: rad into a tag in m is another
  // dimension, into mrad off by 1000; a tag without a unit takes any.
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: LREAL, unit: m}
  - {name: b, type: LREAL, unit: mrad}
  - {name: c, type: LREAL}
  - {name: d, type: LREAL, unit: rad}
drivers:
  - name: io
    type: memory
    channels: [{name: p1, dir: in, type: LREAL, unit: rad}, {name: p2, dir: in, type: LREAL, unit: rad},
               {name: p3, dir: in, type: LREAL, unit: rad}, {name: p4, dir: in, type: LREAL, unit: rad}]
    bind: {p1: a, p2: b, p3: c, p4: d}
)");
  EXPECT_THAT(e, ElementsAre("p.yaml:12:16: unit mismatch: channel io.p1 is in rad, tag a in m (another dimension)",
                             "p.yaml:12:23: unit mismatch: channel io.p2 is in rad, tag b in mrad (the driver copies the "
                             "value: give the tag the channel's unit, or scale it with a MUL block)"));
}

// --- traces and watch ------------------------------------------------------------------------

TEST(LoadErrors, TracesAndWatchNamingUnknownThings) {
  // Element references go in block lists (or quoted): in a flow list [a[1]]
  // the brackets are YAML syntax.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: lamp, type: BOOL}, {name: arr, type: "ARRAY[0..1] OF INT"}]
blocks: [{name: t, type: TON, inputs: {IN: TRUE, PT: 1s}}]
connections: [t.Q -> lamp]
traces:
  - nosuch
  - t.Q
  - t.XX
  - ghost.Q
  - arr
  - arr[1]
  - arr[2]
watch: [lamp, nosuch2, t.Q]
)"),
              ElementsAre("p.yaml:6:5: trace: unknown tag or instance.pin 'nosuch'",
                          "p.yaml:8:5: trace: block t (TON) has no pin 'XX' (IN, PT, Q, ET, ENO)",
                          "p.yaml:9:5: trace: unknown block instance 'ghost'",
                          "p.yaml:10:5: trace: arr is an array; trace its elements (arr[i])",
                          "p.yaml:12:5: trace: index 2 is outside arr[0..1]",
                          "p.yaml:13:15: watch: unknown tag 'nosuch2'", "p.yaml:13:24: watch: unknown tag 't.Q'"));
}

// --- --set overrides ---------------------------------------------------------------------------

TEST(LoadErrors, OverridesNamingUnknownThings) {
  LoadOptions o;
  o.blocks = &param_blocks();
  o.overrides = {{"ghost", "K", "2"}, {"g", "Q", "2"}, {"g", "IN", "2"}, {"g", "K", "500"}, {"g", "N", "x"},
                 {"lamp", "", "maybe"}};
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: lamp, type: BOOL}]
blocks: [{name: g, type: GAIN, inputs: {IN: 1}}]
)",
                     o),
              ElementsAre("command line:0:0: --set ghost.K: no block instance 'ghost'",
                          "command line:0:0: --set g.Q: GAIN has no parameter 'Q'",
                          "command line:0:0: --set g.IN: that is a pin; --set takes parameters",
                          "command line:0:0: --set init of lamp: 'maybe' is not a BOOL (TRUE or FALSE)",
                          "command line:0:0: g.K = 500 is outside its range 0 .. 100 m/s",
                          "command line:0:0: g.N: 'x' is not an integer"));
}

TEST(LoadErrors, OverrideValuesCheckedLikeTheFile) {
  LoadOptions o;
  o.blocks = &param_blocks();
  o.overrides = {{"g", "K", "500"}, {"g", "N", "x"}};
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks: [{name: g, type: GAIN, inputs: {IN: 1}}]
)",
                     o),
              ElementsAre("command line:0:0: g.K = 500 is outside its range 0 .. 100 m/s",
                          "command line:0:0: g.N: 'x' is not an integer"));
}

// --- everything at once ------------------------------------------------------------------------

TEST(LoadErrors, AllErrorsAreReportedAtOnce) {
  auto r = load(R"(
project: {name: demo, seed: -3}
tasks:
  - {name: fast, period: 1 ms x, priority: 120}
  - {name: slow, period: 10ms, phase: 10ms, watchdog: {time: 1ms, action: reboot}}
tags:
  - {name: a, type: INT, init: 40000}
  - {name: b, type: BOOL, address: "%IW0"}
  - {name: c, type: LREAL, unit: m/s, init: 3 kg}
  - {name: a, type: BOOL}
blocks:
  - {name: t1, type: TONX, task: fast}
  - {name: t2, type: TON, task: fast, inputs: {XX: 1}}
  - {name: t3, type: TON, task: slow}
connections:
  - b t2.IN
  - b -> t2.PT
  - t2.Q -> t3.IN
bogus: 1
)");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.program, nullptr);
  EXPECT_THAT(errors(r),
              ElementsAre("p.yaml:1:29: seed: value -3 is out of range for ULINT (unsigned)",
                          "p.yaml:3:26: period: '1 ms x' is not a duration (no space may separate 1 from its unit: 1ms; "
                          "write e.g. 1ms, 250us, 0.5s, T#1m30s)",
                          "p.yaml:3:44: priority 120 is outside 1..99 (SCHED_FIFO; higher runs first)",
                          "p.yaml:4:39: phase must be shorter than the period",
                          "p.yaml:4:75: watchdog action must be log, stop or safe_stop, not 'reboot'",
                          "p.yaml:6:32: init of a: value 40000 is out of range for INT (-32768 .. 32767)",
                          "p.yaml:7:36: a BOOL cannot sit at %IW0 (16-bit address; use X)",
                          "p.yaml:8:45: init of c: unit 'kg' is not compatible with 'm/s'",
                          "p.yaml:9:12: duplicate name 'a' (first defined at p.yaml:6:12)",
                          "p.yaml:11:22: unknown block type 'TONX' (see `syncplc blocks`)",
                          "p.yaml:12:52: block t2 (TON) has no pin 'XX' (IN, PT, Q, ET, ENO)",
                          "p.yaml:15:5: a connection is written 'source.pin -> target.pin'",
                          "p.yaml:16:5: type mismatch: b is BOOL, t2.PT is TIME",
                          "p.yaml:17:5: blocks in different tasks exchange data through a tag: connect t2.Q -> a tag "
                          "-> t3.IN",
                          "p.yaml:18:8: unknown top-level key 'bogus' (project, include, tasks, tags, blocks, programs, sources, "
                          "connections, drivers, traces, watch, metrics, modbus, store)"));
}

TEST(LoadErrors, DiagnosticsCarryStructuredPlaces) {
  auto r = load(R"(
tasks: [{name: main, period: 5q}]
)");
  ASSERT_EQ(r.diagnostics.size(), 1u);
  const Diagnostic& d = r.diagnostics.list()[0];
  EXPECT_EQ(d.loc.file, "p.yaml");
  EXPECT_EQ(d.loc.line, 1);
  EXPECT_EQ(d.loc.col, 30);
  EXPECT_THAT(d.message, ::testing::HasSubstr("unknown unit 'q'"));
}

}  // namespace
}  // namespace syncplc::loadertest

namespace syncplc::loadertest {
namespace {

// --- integer arithmetic on user input is overflow-checked -------------------------

TEST(LoadErrors, ArrayBoundsThatOverflowAreErrors) {
  // hi - lo + 1 wrapped to 0 for the full 64-bit range: a 0-cell tag loaded.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: "ARRAY[-9223372036854775808..9223372036854775807] OF INT"}
  - {name: b, type: "ARRAY[0..99999999999999999999] OF INT"}
  - {name: c, type: "ARRAY[9223372036854775807..-9223372036854775808] OF INT"}
  - {name: d, type: "ARRAY[-9223372036854775808..-9223372036854775808] OF INT"}
)"),
              ElementsAre("p.yaml:3:21: array bounds of 'ARRAY[-9223372036854775808..9223372036854775807] OF INT' "
                          "must give 1..65536 elements",
                          "p.yaml:4:21: bad array bounds in 'ARRAY[0..99999999999999999999] OF INT' (whole numbers "
                          "that fit 64 bits)",
                          "p.yaml:5:21: array bounds of 'ARRAY[9223372036854775807..-9223372036854775808] OF INT' "
                          "must give 1..65536 elements"));
}

TEST(LoadErrors, ArrayBoundsAtTheEndsOfTheRangeWork) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: lo, type: "ARRAY[-9223372036854775808..-9223372036854775805] OF INT"}
  - {name: hi, type: "ARRAY[9223372036854775806..9223372036854775807] OF INT"}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->find_tag("lo")->length, 4u);
  EXPECT_EQ(r.program->find_tag("hi")->length, 2u);
  EXPECT_EQ(r.program->resolve("hi[9223372036854775807]")->cell, r.program->find_tag("hi")->cell + 1);
}

TEST(LoadErrors, IndicesThatOverflowAreOutsideTheArray) {
  // index - lower overflowed for an index near -2^63 and a positive lower bound.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: arr, type: "ARRAY[1..4] OF LREAL"}
  - {name: top, type: "ARRAY[9223372036854775806..9223372036854775807] OF LREAL"}
blocks:
  - {name: m, type: MOVE}
  - {name: n, type: MOVE}
connections:
  - arr[-9223372036854775808] -> m.IN
  - top[-9223372036854775808] -> n.IN
  - m.OUT -> arr[99999999999999999999]
traces: ["arr[-9223372036854775807]"]
)"),
              ElementsAre("p.yaml:9:5: index -9223372036854775808 is outside arr[1..4]",
                          "p.yaml:10:5: index -9223372036854775808 is outside top[9223372036854775806..9223372036854775807]",
                          "p.yaml:11:14: bad array index in 'arr[99999999999999999999]'",
                          "p.yaml:12:10: trace: index -9223372036854775807 is outside arr[1..4]"));
}

TEST(LoadErrors, WatchdogTimesThatWouldOverflowAreErrors) {
  // The runtime multiplies the time by the sensitivity (up to 1000).
  EXPECT_THAT(errors(R"(
tasks:
  - {name: main, period: 1ms, watchdog: {time: 100000d, sensitivity: 1000}}
)"),
              ElementsAre("p.yaml:2:48: watchdog time 100000d is longer than 1h"));
}

// --- writes from outside that the program would overwrite every scan -------------------

TEST(LoadErrors, HmiReadwriteTagWrittenByABlockOrADriverEveryScan) {
  // An HMI (Modbus) write would be overwritten by the writer in the same scan.
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: go, type: BOOL, hmi: readwrite}
  - {name: lamp, type: BOOL, hmi: readwrite}
  - {name: arr, type: "ARRAY[1..2] OF BOOL", hmi: readwrite}
  - {name: half, type: "ARRAY[1..2] OF BOOL", hmi: readwrite}
  - {name: sp, type: BOOL, hmi: readwrite}
blocks:
  - {name: n, type: NOT}
  - {name: m, type: NOT, inputs: {IN: TRUE}}
connections:
  - sp -> n.IN
  - n.OUT -> lamp
  - n.OUT -> arr[1]
  - m.OUT -> arr[2]
  - m.OUT -> half[1]
drivers:
  - {name: io, type: memory, channels: [{name: b, dir: in, type: BOOL}], bind: {b: go}}
)");
  EXPECT_THAT(e, has_error("p.yaml:3:33", "tag go is hmi: readwrite, but driver io.b (p.yaml:18:84) writes it every scan "
                                          "and wins: an HMI write would be overwritten in the same scan; make it hmi: read, "
                                          "or give the HMI a tag of its own"));
  EXPECT_THAT(e, has_error("p.yaml:4:35", "tag lamp is hmi: readwrite, but block n.OUT (p.yaml:13:5) writes it every scan"));
  // Every element written by some block: written every scan too.
  EXPECT_THAT(e, has_error("p.yaml:5:51", "tag arr is hmi: readwrite, but block n.OUT (p.yaml:14:5) writes it every scan"));
  // One element written: a write of the whole array would lose it.
  EXPECT_THAT(e, has_error("p.yaml:6:52", "tag half is hmi: readwrite, but block m.OUT (p.yaml:16:5) writes elements of "
                                          "it every scan"));
  // sp is read by a block and written by nobody: an HMI may write it.
  EXPECT_THAT(e, ::testing::SizeIs(4));
}

TEST(LoadErrors, SetOnATagWrittenEveryScan) {
  LoadOptions o;
  o.overrides = {{"lamp", "", "TRUE"}, {"go", "", "TRUE"}, {"sp", "", "2.5"}};
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: go, type: BOOL}
  - {name: lamp, type: BOOL}
  - {name: sp, type: LREAL}
blocks:
  - {name: n, type: NOT}
  - {name: g, type: GAIN}
connections:
  - go -> n.IN
  - n.OUT -> lamp
  - sp -> g.IN
drivers:
  - {name: io, type: memory, channels: [{name: b, dir: in, type: BOOL}], bind: {b: go}}
)",
                  [&] { o.blocks = &param_blocks(); return o; }());
  EXPECT_THAT(e, ElementsAre("command line:0:0: --set go: driver io.b (p.yaml:14:84) writes the tag every scan and wins: "
                             "the value would be overwritten on the first scan; set the driver's settings (--set "
                             "io.key=value), or in a scan-cycle test its channel io.b",
                             "command line:0:0: --set lamp: block n.OUT (p.yaml:11:5) writes the tag every scan and wins: "
                             "the value would be overwritten on the first scan; set what block n reads: its parameters "
                             "(--set n.param=value) or the tags wired to its inputs"));
}

TEST(LoadErrors, SimRingLossTakesNoBind) {
  // bind: (and late:) belong to the driver, not to its loss: section.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: sent, type: ULINT}]
drivers:
  - name: ring
    type: sim_ring
    loss: {model: bernoulli, p: 0.1, bind: {frames_sent: sent}, late: 0.1}
    bus: {type: ethercat, bind: {}}
)"),
              ElementsAre("p.yaml:6:11: loss: see the errors above",
                          "p.yaml:6:44: unknown key 'bind' in loss (model, p, p_good_bad, p_bad_good, loss_good, "
                          "loss_bad, scope)",
                          "p.yaml:6:71: unknown key 'late' in loss (model, p, p_good_bad, p_bad_good, loss_good, "
                          "loss_bad, scope)",
                          "p.yaml:7:10: bus: see the errors above",
                          "p.yaml:7:33: unknown key 'bind' in bus (type, bandwidth, payload, overhead, hop_delay, "
                          "gap_count, exec_time, alpha)"));
}

TEST(LoadErrors, MisspeltParameterInABlockFactory) {
  // The factory reads "nmae"; the type declares "name": a load error, not an out-of-range read.
  BlockRegistry reg;
  BlockTypeInfo t;
  t.name = "TYPO";
  t.category = "test";
  t.params = {parameter("name", IecType::LREAL).init("1")};
  struct Typo final : Block {
    explicit Typo(BlockSetup& s) : v(s.param<double>("nmae")) {}
    void execute(ScanContext&) noexcept override {}
    double v;
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<Typo>(s); };
  reg.add(std::move(t));
  LoadOptions o;
  o.blocks = &reg;
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: t, type: TYPO}
)",
                     o),
              ElementsAre("p.yaml:3:5: t (TYPO): its factory reads parameter 'nmae', which TYPO does not declare (name)"));
}

// --- messages that say what is wrong ---------------------------------------------------

TEST(LoadErrors, SpaceInsideADurationIsNamed) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 10 ms}]
)"),
              ElementsAre("p.yaml:1:30: period: '10 ms' is not a duration (no space may separate 10 from its unit: "
                          "10ms; write e.g. 1ms, 250us, 0.5s, T#1m30s)"));
}

TEST(LoadErrors, YamlSyntaxErrorsHintAtTabsAndPercentSigns) {
  EXPECT_THAT(errors("tasks:\n\t- {name: main, period: 1ms}\n"),
              ElementsAre("p.yaml:2:1: YAML syntax error: found character that cannot start any token (the line has a "
                          "tab: YAML indents with spaces only)"));
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: BOOL, address: %IX0.0}
)"),
              ElementsAre("p.yaml:3:36: YAML syntax error: found character that cannot start any token (a value "
                          "starting with % must be quoted, "
                          "e.g. address: \"%IX0.0\")"));
  // Quoted, a % is no hint's business.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms
tags:
  - {name: a, type: BOOL, address: "%IX0.0"}
)"),
              ElementsAre("p.yaml:2:5: YAML syntax error: did not find expected ',' or '}' (while parsing a flow "
                          "mapping that starts at line 1, column 9)"));
}

TEST(LoadErrors, UnitWithoutCaretSuggestsOne) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: LREAL, unit: m/s2}
  - {name: b, type: LREAL, unit: m/s3x}
)"),
              ElementsAre("p.yaml:3:34: bad unit 'm/s2': unexpected text (powers are written with ^: 'm/s^2')",
                          "p.yaml:4:34: bad unit 'm/s3x': unexpected text"));
}

TEST(LoadErrors, UnitsAreCheckedAcrossConnections) {
  // GAIN's OUT and IN are LREAL; its K is in m/s. Tags carry units.
  LoadOptions o;
  o.blocks = &param_blocks();
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: dist, type: LREAL, unit: m}
  - {name: angle, type: LREAL, unit: rad}
  - {name: small, type: LREAL, unit: mm}
  - {name: same, type: LREAL, unit: m}
  - {name: free, type: LREAL}
blocks:
  - {name: g1, type: GAIN}
  - {name: g2, type: GAIN}
  - {name: g3, type: GAIN}
connections:
  - dist -> g1.IN
  - g1.OUT -> angle
  - free -> g2.IN
  - g2.OUT -> small
  - same -> g3.IN
  - g3.OUT -> dist
)",
                  o);
  // GAIN's pins carry no unit: any tag connects to them.
  EXPECT_THAT(e, ::testing::IsEmpty());
  auto e2 = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: dist, type: LREAL, unit: m}
  - {name: angle, type: LREAL, unit: rad}
  - {name: small, type: LREAL, unit: mm}
  - {name: ok, type: LREAL, unit: m}
blocks:
  - {name: c1, type: SYNC_CONTROLLER}
  - {name: c2, type: SYNC_CONTROLLER}
  - {name: c3, type: SYNC_CONTROLLER}
connections:
  - dist -> c1.x
  - small -> c2.x
  - angle -> c3.x
)");
  EXPECT_THAT(e2, has_error("p.yaml:12:5", "unit mismatch: dist is in m, c1.x in rad (another dimension)"));
  EXPECT_THAT(e2, has_error("p.yaml:13:5", "unit mismatch: small is in mm, c2.x in rad (another dimension)"));
  EXPECT_THAT(e2, ::testing::Not(::testing::Contains(::testing::StartsWith("p.yaml:14:5"))));
}

TEST(LoadErrors, UnitsOfTheSameDimensionButAnotherScaleAreAMismatch) {
  // A connection copies the value: mm into m would be off by 1000.
  auto e = errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: deg, type: LREAL, unit: deg}
  - {name: rad, type: LREAL, unit: rad}
blocks:
  - {name: c, type: SYNC_CONTROLLER}
  - {name: d, type: SYNC_CONTROLLER}
connections:
  - deg -> c.x
  - rad -> d.x
)");
  EXPECT_THAT(e, has_error("p.yaml:9:5", "unit mismatch: deg is in deg, c.x in rad (a connection copies the value: "
                                         "scale it with a MUL block, or give both ends one unit)"));
  EXPECT_THAT(e, ::testing::Not(::testing::Contains(::testing::StartsWith("p.yaml:10:5"))));
}

// One load reports the errors of every phase together, and a declaration that
// failed causes no follow-on errors where it is used.
TEST(LoadErrors, EveryPhaseReportsInOneLoadWithoutFollowOnErrors) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: lamp, type: BOOL}
  - {name: bad, type: WIBBLE}
blocks:
  - {name: x, type: NOPE}
  - {name: a, type: AND}
  - {name: n, type: NOT}
  - {name: t, type: TON, inputs: {IN: TRUE, PT: soon}}
connections:
  - x.Q -> lamp
  - bad -> a.IN2
  - a.OUT -> n.IN
  - n.OUT -> a.IN1
traces: [x.Q, bad, t.ET, t.QQ]
)"),
              ElementsAre("p.yaml:4:23: unknown IEC type 'WIBBLE' (BOOL, SINT, INT, DINT, LINT, USINT, UINT, UDINT, "
                          "ULINT, BYTE, WORD, DWORD, LWORD, REAL, LREAL, TIME or ARRAY[a..b] OF type)",
                          "p.yaml:6:21: unknown block type 'NOPE' (see `syncplc blocks`)",
                          "p.yaml:9:49: t.PT: 'soon' is not a duration (missing number; write e.g. 1ms, 250us, 0.5s, T#1m30s)",
                          "p.yaml:14:5: feedback loop without a one-scan delay: a -> n -> a (break it with a UNIT_DELAY block)",
                          "p.yaml:15:26: trace: block t (TON) has no pin 'QQ' (IN, PT, Q, ET, ENO)"));
}

}  // namespace
}  // namespace syncplc::loadertest
