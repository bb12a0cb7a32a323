// Projects that load: the example project, the tag map (owner task, cells),
// generic type inference, execution order, arrays, values, --set overrides,
// seeds, snapshot wiring and safe values.
#include <algorithm>
#include <limits>

#include "tests/support/image_key.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;

std::vector<std::string> order_of(const Program& p, const std::string& task) {
  std::vector<std::string> v;
  for (const auto& b : p.tasks[static_cast<std::size_t>(p.find_task(task))]->blocks) v.push_back(b.name);
  return v;
}

const BlockInstance& instance(const Program& p, const std::string& name) {
  auto [t, k] = p.instances.at(name);
  return p.tasks[t]->blocks[k];
}

Cell init_cell(const Program& p, const std::string& tag, std::uint32_t element = 0) {
  const Tag* t = p.find_tag(tag);
  return p.tasks[t->owner]->image(::syncplc::testing::image_key())[t->cell + element];
}

// --- the example project ---------------------------------------------------------------

TEST(LoadOk, BottleLine) {
  auto r = load_project(SYNCPLC_SOURCE_DIR "/projects/bottle_line/bottle_line.yaml");
  ASSERT_LOADS(r);
  EXPECT_TRUE(r.diagnostics.empty());
  const Program& p = *r.program;
  EXPECT_EQ(p.name, "bottle_line");
  EXPECT_EQ(p.version, "1.0.0");
  ASSERT_EQ(p.tasks.size(), 2u);
  const auto& line = p.tasks[0]->config();
  EXPECT_EQ(line.name, "line");
  EXPECT_EQ(line.period_ns, 1'000'000);
  EXPECT_EQ(line.priority, 80);
  EXPECT_TRUE(line.watchdog);
  EXPECT_EQ(line.watchdog_ns, 800'000);
  EXPECT_EQ(line.sensitivity, 3);
  EXPECT_EQ(line.action, WatchdogAction::SafeStop);
  const auto& filler = p.tasks[1]->config();
  EXPECT_EQ(filler.period_ns, 10'000'000);
  EXPECT_EQ(filler.phase_ns, 500'000);
  EXPECT_EQ(filler.missed, MissedCycles::Skip);

  // Unit delays first, then data order.
  auto order = order_of(p, "line");
  ASSERT_GE(order.size(), 3u);
  EXPECT_EQ(order[0], "conveyor_fb");
  EXPECT_EQ(order[1], "gap_fb");
  EXPECT_EQ(p.tasks[0]->unit_delays, 2u);
  auto pos = [&](const std::string& n) { return std::find(order.begin(), order.end(), n) - order.begin(); };
  EXPECT_LT(pos("start_edge"), pos("run_latch"));
  EXPECT_LT(pos("bottle_edge"), pos("batch_counter"));
  EXPECT_LT(pos("batch_counter"), pos("stop_request"));  // batch_done is written before it is read
  EXPECT_THAT(order_of(p, "filler"), ElementsAre("fill_pulse", "speed_select"));

  // Tag map.
  auto owner = [&](const std::string& tag) { return p.tasks[p.find_tag(tag)->owner]->config().name; };
  EXPECT_EQ(owner("start_button"), "line");   // driver panel (task line) writes it
  EXPECT_EQ(owner("bottles"), "line");        // batch_counter.CV
  EXPECT_EQ(owner("fill_valve"), "filler");   // fill_pulse.Q
  EXPECT_EQ(owner("fill_time"), "filler");    // only read, by fill_pulse
  EXPECT_EQ(owner("auto_mode"), "line");      // only read, by may_restart
  EXPECT_EQ(p.find_tag("start_button")->writer, "driver panel.start");
  EXPECT_EQ(p.find_tag("bottles")->writer, "block batch_counter.CV");
  EXPECT_EQ(p.find_tag("auto_mode")->writer, "");
  const Tag* speed = p.find_tag("nominal_speed");
  EXPECT_EQ(speed->unit, "m/s");
  EXPECT_DOUBLE_EQ(speed->init[0].get<double>(), 0.35);  // 21 m/min
  EXPECT_EQ(p.find_tag("batch_size")->address->text(), "%MW2");
  EXPECT_TRUE(p.find_tag("batch_size")->retain);
  EXPECT_EQ(p.find_tag("batch_size")->hmi, HmiAccess::ReadWrite);
  EXPECT_EQ(p.find_tag("bottles")->hmi, HmiAccess::Read);
  EXPECT_EQ(instance(p, "batch_counter").datatype, IecType::INT);
  EXPECT_EQ(instance(p, "conveyor_fb").datatype, IecType::BOOL);
  EXPECT_EQ(instance(p, "speed_select").datatype, IecType::LREAL);

  EXPECT_EQ(p.drivers.size(), 2u);
  EXPECT_EQ(p.traces.size(), 7u);
  EXPECT_EQ(p.traces.back().label, "restart_delay.ET");
  EXPECT_EQ(p.watch.size(), 6u);

  // Modbus: the server's settings and the explicitly placed setpoints.
  const ModbusSettings& m = r.modbus;
  EXPECT_TRUE(m.server.enabled);
  EXPECT_EQ(m.server.port, 5020);
  EXPECT_EQ(m.server.bind, "127.0.0.1");
  ASSERT_EQ(m.places.size(), p.tags.size()) << "one entry a tag";
  auto place = [&](const std::string& tag) { return explicit_place(m.places, p.find_tag(tag) - p.tags.data()); };
  ASSERT_TRUE(place("nominal_speed"));
  EXPECT_EQ(place("nominal_speed")->table, ModbusTable::HoldingRegisters);
  EXPECT_EQ(place("nominal_speed")->address, 3000u);
  EXPECT_EQ(place("auto_mode")->table, ModbusTable::Coils);
  EXPECT_FALSE(place("batch_size")) << "placed by its %MW2";
}

TEST(LoadOk, BottleLineAsTextGivesTheSameMessagesName) {
  // load_project_text names the file in places and in Program::file.
  auto r = load_project_text("tasks: [{name: t, period: 1ms}]\n", "inline.yaml");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->file, "inline.yaml");
  EXPECT_EQ(r.program->name, "unnamed");
  EXPECT_EQ(r.program->version, "0");
}

// --- defaults -----------------------------------------------------------------------------------

TEST(LoadOk, TaskAndTagDefaults) {
  auto r = load(R"(
tasks: [{name: main, period: 2ms}]
tags: [{name: x, type: LREAL}]
)");
  ASSERT_LOADS(r);
  const auto& c = r.program->tasks[0]->config();
  EXPECT_EQ(c.phase_ns, 0);
  EXPECT_EQ(c.priority, 50);
  EXPECT_FALSE(c.watchdog);
  EXPECT_EQ(c.missed, MissedCycles::Skip);
  EXPECT_EQ(c.cpu, -1);
  EXPECT_EQ(c.write_queue, 1024u);
  const Tag* x = r.program->find_tag("x");
  EXPECT_EQ(x->hmi, HmiAccess::None);
  EXPECT_FALSE(x->retain);
  EXPECT_FALSE(x->address.has_value());
  EXPECT_TRUE(x->safe.empty());
  EXPECT_EQ(x->init[0].raw, 0u);
}

TEST(LoadOk, AllTaskSettings) {
  auto r = load(R"(
tasks:
  - name: t
    period: T#1s
    phase: 250ms
    priority: 99
    cpu: 3
    missed_cycles: immediate
    write_queue: 16
    watchdog: {time: 100ms, sensitivity: 1000, action: stop}
)");
  ASSERT_LOADS(r);
  const auto& c = r.program->tasks[0]->config();
  EXPECT_EQ(c.period_ns, 1'000'000'000);
  EXPECT_EQ(c.phase_ns, 250'000'000);
  EXPECT_EQ(c.priority, 99);
  EXPECT_EQ(c.cpu, 3);
  EXPECT_EQ(c.missed, MissedCycles::Immediate);
  EXPECT_EQ(c.write_queue, 16u);
  EXPECT_EQ(c.watchdog_ns, 100'000'000);
  EXPECT_EQ(c.sensitivity, 1000);
  EXPECT_EQ(c.action, WatchdogAction::Stop);
}

TEST(LoadOk, TheDefaultWriteQueueGrowsToTheLargestModbusWrite) {
  // FC 15 can carry 1968 coils, FC 16 123 registers: what one request can queue
  // to a task must fit its queue (applied whole in one scan).
  auto r = load(R"(
tasks:
  - {name: coils, period: 1ms}
  - {name: regs, period: 1ms}
  - {name: few, period: 1ms, write_queue: 16}
tags:
  - {name: valves, type: "ARRAY[0..2999] OF BOOL", address: "%QX0.0", hmi: readwrite, task: coils}
  - {name: sp, type: "ARRAY[0..999] OF INT", address: "%MW0", hmi: readwrite, task: regs}
  - {name: trims, type: "ARRAY[0..15] OF LREAL", address: "%ML300", hmi: readwrite, task: few}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->tasks[0]->config().write_queue, 1968u);
  EXPECT_EQ(r.program->tasks[1]->config().write_queue, 1024u) << "123 fit the default";
  EXPECT_EQ(r.program->tasks[2]->config().write_queue, 16u) << "16 values, 64 registers";
}

TEST(LoadOk, AReadOnlyModbusServerQueuesNothingSoAnyWriteQueueWillDo) {
  auto r = load(R"(
tasks:
  - {name: a, period: 1ms, write_queue: 16}
tags:
  - {name: sp, type: "ARRAY[0..19] OF INT", address: "%MW0", hmi: readwrite}
modbus: {read_only: true}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->tasks[0]->config().write_queue, 16u);
}

TEST(LoadOk, PeriodLimitsAreInclusive) {
  ASSERT_LOADS(load("tasks: [{name: a, period: 100us}, {name: b, period: 10s}, {name: c, period: 0.5ms}]\n"));
}

// --- tag ownership and cells ------------------------------------------------------------------

TEST(LoadOk, TagOwnerIsTheWriterElseTaskElseFirstReader) {
  auto r = load(R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: unused, type: INT}
  - {name: by_block, type: BOOL}
  - {name: by_key, type: BOOL, task: slow}
  - {name: by_reader, type: BOOL}
  - {name: by_driver, type: BOOL}
  - {name: to_driver, type: BOOL}
blocks:
  - {name: w, type: NOT, task: slow, inputs: {IN: TRUE}}
  - {name: r1, type: NOT, task: slow}
  - {name: r2, type: NOT, task: fast}
  - {name: r3, type: NOT, task: fast}
connections:
  - w.OUT -> by_block
  - by_reader -> r1.IN
  - by_reader -> r2.IN
  - by_block -> r3.IN
drivers:
  - name: io
    type: memory
    task: fast
    channels: [{name: i, dir: in, type: BOOL}, {name: o, dir: out, type: BOOL}]
    bind: {i: by_driver, o: to_driver}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  auto owner = [&](const char* tag) { return p.find_tag(tag)->owner; };
  EXPECT_EQ(owner("unused"), 0);     // nobody: the first task
  EXPECT_EQ(owner("by_block"), 1);   // written by w in slow (read by fast)
  EXPECT_EQ(owner("by_key"), 1);     // task: slow
  EXPECT_EQ(owner("by_reader"), 1);  // read first by r1 (slow), then by r2 (fast)
  EXPECT_EQ(owner("by_driver"), 0);  // written by io.i in fast
  EXPECT_EQ(owner("to_driver"), 0);  // read by io.o in fast
  EXPECT_EQ(p.find_tag("by_driver")->writer, "driver io.i");
  EXPECT_EQ(p.find_tag("by_block")->writer, "block w.OUT");

  // Owned tags first in each owner's image, in declaration order.
  EXPECT_EQ(p.find_tag("unused")->cell, 0u);
  EXPECT_EQ(p.find_tag("by_driver")->cell, 1u);
  EXPECT_EQ(p.find_tag("to_driver")->cell, 2u);
  EXPECT_EQ(p.tasks[0]->owned_cells, 3u);
  EXPECT_EQ(p.find_tag("by_block")->cell, 0u);
  EXPECT_EQ(p.find_tag("by_key")->cell, 1u);
  EXPECT_EQ(p.find_tag("by_reader")->cell, 2u);
  EXPECT_EQ(p.tasks[1]->owned_cells, 3u);
  // fast reads two of slow's tags through one snapshot channel; slow reads nothing.
  ASSERT_EQ(p.tasks[0]->inbound.size(), 1u);
  EXPECT_EQ(p.tasks[0]->inbound[0].producer, 1u);
  EXPECT_EQ(p.tasks[0]->inbound[0].copies.size(), 2u);
  EXPECT_TRUE(p.tasks[1]->inbound.empty());
  // channels: [0] for other threads, then one per consuming task.
  EXPECT_EQ(p.tasks[1]->channels.size(), 2u);
  EXPECT_EQ(p.tasks[0]->channels.size(), 1u);
  // image: owned | foreign copies | pins (two blocks of two pins and ENO)
  EXPECT_EQ(p.tasks[0]->image_cells(), 3u + 2u + 2u * 3u);
}

TEST(LoadOk, ArrayTagsTakeLengthCells) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: BOOL}
  - {name: arr, type: "ARRAY[1..4] OF INT", init: [10, 20, 30, 40]}
  - {name: b, type: BOOL}
)");
  ASSERT_LOADS(r);
  const Tag* arr = r.program->find_tag("arr");
  EXPECT_TRUE(arr->is_array);
  EXPECT_EQ(arr->length, 4u);
  EXPECT_EQ(arr->array_lower, 1);
  EXPECT_EQ(arr->type, IecType::INT);
  EXPECT_EQ(arr->cell, 1u);
  EXPECT_EQ(r.program->find_tag("b")->cell, 5u);
  for (std::uint32_t i = 0; i < 4; ++i) EXPECT_EQ(init_cell(*r.program, "arr", i).get<std::int16_t>(), 10 * (i + 1));
}

// --- snapshots between tasks --------------------------------------------------------------

TEST(LoadOk, AReaderTaskSeesTheOwnersPublishedValue) {
  auto r = load(R"(
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: count, type: INT}
  - {name: copy, type: INT}
blocks:
  - {name: c, type: CTU, task: fast, inputs: {CU: TRUE, PV: 100}}
  - {name: edge, type: NOT, task: fast}
  - {name: mv, type: MOVE, task: slow}
connections:
  - c.CV -> count
  - count -> mv.IN
  - mv.OUT -> copy
  - c.Q -> edge.IN
)");
  ASSERT_LOADS(r);
  Program& p = *r.program;
  EXPECT_EQ(instance(p, "mv").datatype, IecType::INT);  // inferred across the task boundary
  // CU is TRUE all along: CTU counts once (edge memory starts FALSE) in
  // fast's first scan, visible to slow from 1 ms on: slow's scan at 10 ms.
  VirtualClock clock(p);
  clock.run_until(0, true);
  const Tag* copy0 = p.find_tag("copy");
  EXPECT_EQ(p.live_cell({copy0->owner, copy0->cell, IecType::INT, 1}, ::syncplc::testing::image_key())->get<std::int16_t>(), 0) << "not visible at 0";
  clock.run_until(10'000'000, true);
  const Tag* copy = p.find_tag("copy");
  EXPECT_EQ(p.live_cell({copy->owner, copy->cell, IecType::INT, 1}, ::syncplc::testing::image_key())->get<std::int16_t>(), 1);
}

// --- generic type inference ---------------------------------------------------------------

TEST(LoadOk, GenericTakesTheTypeOfItsTags) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: INT}
  - {name: b, type: INT}
  - {name: sum, type: INT}
blocks:
  - {name: add, type: ADD}
connections:
  - a -> add.IN1
  - b -> add.IN2
  - add.OUT -> sum
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(instance(*r.program, "add").datatype, IecType::INT);
}

TEST(LoadOk, AChainOfGenericBlocksInheritsTheType) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: DINT}
  - {name: out, type: BOOL}
blocks:
  - {name: cmp, type: GT, inputs: {IN2: 100}}
  - {name: lim, type: LIMIT, inputs: {MN: -5, MX: 5000}}
  - {name: mul, type: MUL, inputs: {IN2: 3}}
  - {name: add, type: ADD, inputs: {IN2: 1}}
connections:
  - a -> add.IN1
  - add.OUT -> mul.IN1
  - mul.OUT -> lim.IN
  - lim.OUT -> cmp.IN1
  - cmp.OUT -> out
)");
  ASSERT_LOADS(r);
  for (const char* n : {"add", "mul", "lim", "cmp"}) EXPECT_EQ(instance(*r.program, n).datatype, IecType::DINT) << n;
  // Constants on generic pins are read in the inferred type.
  const auto& lim = instance(*r.program, "lim");
  EXPECT_EQ(r.program->tasks[0]->image(::syncplc::testing::image_key())[lim.pin_cell[0]].get<std::int32_t>(), -5);
}

TEST(LoadOk, InferenceRunsBackwardsFromAnOutput) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: t, type: TIME}]
blocks:
  - {name: mv, type: MOVE}
  - {name: add, type: ADD, inputs: {IN1: 1s, IN2: 250ms}}
connections:
  - add.OUT -> mv.IN
  - mv.OUT -> t
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(instance(*r.program, "mv").datatype, IecType::TIME);
  EXPECT_EQ(instance(*r.program, "add").datatype, IecType::TIME);
}

TEST(LoadOk, UnconnectedGenericsTakeTheirDefault) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: add, type: ADD, inputs: {IN1: 1, IN2: 2}}
  - {name: ctu, type: CTU}
  - {name: inv, type: NOT, inputs: {IN: FALSE}}
  - {name: byte, type: NOT, datatype: BYTE, inputs: {IN: 16#0F}}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(instance(*r.program, "add").datatype, IecType::LREAL);
  EXPECT_EQ(instance(*r.program, "ctu").datatype, IecType::INT);
  EXPECT_EQ(instance(*r.program, "inv").datatype, IecType::BOOL);
  EXPECT_EQ(instance(*r.program, "byte").datatype, IecType::BYTE);
}

TEST(LoadOk, DefaultsSpreadToOpenNeighboursWhateverTheDeclarationOrder) {
  // Neither block is tied to a typed tag: CTU's default (INT) must win over
  // MOVE's (LREAL, which CV cannot take), whichever is declared first.
  for (const char* blocks : {"[{name: mv, type: MOVE}, {name: c, type: CTU}]", "[{name: c, type: CTU}, {name: mv, type: MOVE}]"}) {
    std::string text = std::string("tasks: [{name: main, period: 1ms}]\nblocks: ") + blocks + "\nconnections: [c.CV -> mv.IN]\n";
    auto r = load_project_text(text, "p.yaml");
    ASSERT_LOADS(r) << blocks;
    EXPECT_EQ(instance(*r.program, "c").datatype, IecType::INT) << blocks;
    EXPECT_EQ(instance(*r.program, "mv").datatype, IecType::INT) << blocks;
  }
}

TEST(LoadOk, ExplicitDatatypeWins) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: w, type: WORD}]
blocks:
  - {name: mv, type: MOVE, datatype: word}
  - {name: n, type: NOT, inputs: {IN: 16#00FF}}
connections:
  - n.OUT -> mv.IN
  - mv.OUT -> w
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(instance(*r.program, "mv").datatype, IecType::WORD);
  EXPECT_EQ(instance(*r.program, "n").datatype, IecType::WORD);
}

// --- execution order ------------------------------------------------------------------------

TEST(LoadOk, ExecutionOrderIsTopologicalWithDeclarationOrderAsTieBreak) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: x, type: BOOL}
  - {name: y, type: BOOL}
blocks:
  - {name: e, type: NOT}
  - {name: d, type: NOT}
  - {name: free1, type: NOT, inputs: {IN: TRUE}}
  - {name: c, type: NOT}
  - {name: b, type: NOT, inputs: {IN: TRUE}}
  - {name: free2, type: NOT, inputs: {IN: TRUE}}
  - {name: z, type: UNIT_DELAY}
  - {name: a, type: AND}
connections:
  - b.OUT -> c.IN
  - c.OUT -> x
  - x -> d.IN
  - d.OUT -> e.IN
  - z.OUT -> a.IN1
  - e.OUT -> a.IN2
  - a.OUT -> z.IN
  - a.OUT -> y
)");
  ASSERT_LOADS(r);
  // z first (unit delay); then Kahn with a min-heap on declaration index:
  // free1, b, c (via b), d (via tag x), e, free2 ... a after e.
  EXPECT_THAT(order_of(*r.program, "main"), ElementsAre("z", "free1", "b", "c", "d", "e", "free2", "a"));
  EXPECT_EQ(r.program->tasks[0]->unit_delays, 1u);
  EXPECT_EQ(r.program->instances.at("z").second, 0u);
  EXPECT_EQ(r.program->instances.at("a").second, 7u);
}

TEST(LoadOk, NoDependencyThroughATagOfAnotherTask) {
  // b reads x, written by a in another task: b sees last published value,
  // so a loop through two tasks is no loop.
  auto r = load(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 2ms}]
tags: [{name: x, type: BOOL}, {name: y, type: BOOL}]
blocks:
  - {name: a, type: NOT, task: slow}
  - {name: b, type: NOT, task: fast}
connections:
  - y -> a.IN
  - a.OUT -> x
  - x -> b.IN
  - b.OUT -> y
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->find_tag("x")->owner, 1);
  EXPECT_EQ(r.program->find_tag("y")->owner, 0);
}

TEST(LoadOk, ConnectionsBecomeCellCopies) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: go, type: BOOL}, {name: lamp, type: BOOL}]
blocks:
  - {name: t, type: TON, inputs: {PT: 20ms}}
connections:
  - go -> t.IN
  - {from: t.Q, to: lamp}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  const auto& t = instance(p, "t");
  ASSERT_EQ(t.copy_in.size(), 1u);
  EXPECT_EQ(t.copy_in[0].src, p.find_tag("go")->cell);
  EXPECT_EQ(t.copy_in[0].dst, t.pin_cell[0]);
  ASSERT_EQ(t.copy_out.size(), 1u);
  EXPECT_EQ(t.copy_out[0].src, t.pin_cell[2]);
  EXPECT_EQ(t.copy_out[0].dst, p.find_tag("lamp")->cell);
  EXPECT_EQ(p.tasks[0]->image(::syncplc::testing::image_key())[t.pin_cell[1]].get<std::int64_t>(), 20'000'000);  // PT constant
}

// --- arrays ---------------------------------------------------------------------------------------

TEST(LoadOk, ArrayElementsConnectAndInit) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - name: arr
    type: ARRAY[1..4] OF INT          # unquoted only outside {...}: [ ] are YAML syntax there
    init: [1, 2, 3, 4]
  - {name: same, type: "array[0..2] of lreal", init: 1.5}
  - {name: flags, type: "ARRAY[-1..1] OF BOOL", init: [TRUE, FALSE, TRUE]}
blocks:
  - {name: add, type: ADD}
connections:
  - arr[2] -> add.IN1
  - arr[4] -> add.IN2
  - add.OUT -> arr[1]
traces:
  - arr[1]
  - flags[-1]
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  EXPECT_EQ(instance(p, "add").datatype, IecType::INT);  // an element has the element type
  const Tag* arr = p.find_tag("arr");
  const auto& add = instance(p, "add");
  EXPECT_EQ(add.copy_in[0].src, arr->cell + 1);  // arr[2], arr declared 1..4
  EXPECT_EQ(add.copy_in[1].src, arr->cell + 3);
  EXPECT_EQ(add.copy_out[0].dst, arr->cell + 0);
  EXPECT_EQ(arr->writer, "block add.OUT");
  for (std::uint32_t i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(init_cell(p, "same", i).get<double>(), 1.5);
  EXPECT_EQ(p.find_tag("flags")->array_lower, -1);
  EXPECT_TRUE(init_cell(p, "flags", 2).get<bool>());
  ASSERT_EQ(p.traces.size(), 2u);
  EXPECT_EQ(p.traces[0].ref.cell, arr->cell);
  EXPECT_EQ(p.traces[1].ref.cell, p.find_tag("flags")->cell);
  auto ref = p.resolve("arr[4]");
  ASSERT_TRUE(ref.has_value());
  EXPECT_EQ(ref->cell, arr->cell + 3);
}

TEST(LoadOk, ElementDependenciesAreByElement) {
  // b reads arr[1], which a writes: a runs first. a reads arr[2], which
  // nobody in the task writes, and writes arr[1]: no loop through a itself.
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: arr, type: "ARRAY[1..2] OF BOOL"}]
blocks:
  - {name: b, type: NOT}
  - {name: a, type: NOT}
connections:
  - arr[1] -> b.IN
  - arr[2] -> a.IN
  - a.OUT -> arr[1]
)");
  ASSERT_LOADS(r);
  EXPECT_THAT(order_of(*r.program, "main"), ElementsAre("a", "b"));
}

TEST(LoadOk, ArrayBoundToAnArrayChannel) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: ai, type: "ARRAY[0..3] OF REAL", unit: V}]
drivers:
  - name: io
    type: memory
    channels: [{name: analog, dir: in, type: REAL, length: 4, unit: V}]
    bind: {analog: ai}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.program->find_tag("ai")->writer, "driver io.analog");
  EXPECT_EQ(r.program->drivers[0].bound_tags, std::vector<std::string>{"ai"});
}

// --- values, units, addresses, safe values ------------------------------------------------

TEST(LoadOk, ValuesOfEveryType) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: b, type: BOOL, init: true}
  - {name: si, type: SINT, init: -128}
  - {name: i, type: INT, init: "16#7FFF"}
  - {name: di, type: DINT, init: -2_000_000}
  - {name: li, type: LINT, init: LINT#-9223372036854775808}
  - {name: us, type: USINT, init: 2#1111_1111}
  - {name: ui, type: UINT, init: 8#177777}
  - {name: ud, type: UDINT, init: 0xFFFFFFFF}
  - {name: ul, type: ULINT, init: 18446744073709551615}
  - {name: by, type: BYTE, init: 16#A5}
  - {name: w, type: WORD, init: 65535}
  - {name: dw, type: DWORD, init: 0}
  - {name: lw, type: LWORD, init: 16#FFFF_FFFF_FFFF_FFFF}
  - {name: r, type: REAL, init: 1.5e3}
  - {name: lr, type: LREAL, init: -0.25}
  - {name: t, type: TIME, init: T#1m30s}
  - {name: t2, type: TIME, init: 1.5s}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  EXPECT_TRUE(init_cell(p, "b").get<bool>());
  EXPECT_EQ(init_cell(p, "si").get<std::int8_t>(), -128);
  EXPECT_EQ(init_cell(p, "i").get<std::int16_t>(), 32767);
  EXPECT_EQ(init_cell(p, "di").get<std::int32_t>(), -2'000'000);
  EXPECT_EQ(init_cell(p, "li").get<std::int64_t>(), INT64_MIN);
  EXPECT_EQ(init_cell(p, "us").get<std::uint8_t>(), 255);
  EXPECT_EQ(init_cell(p, "ui").get<std::uint16_t>(), 65535);
  EXPECT_EQ(init_cell(p, "ud").get<std::uint32_t>(), 0xFFFFFFFFu);
  EXPECT_EQ(init_cell(p, "ul").get<std::uint64_t>(), UINT64_MAX);
  EXPECT_EQ(init_cell(p, "by").get<std::uint8_t>(), 0xA5);
  EXPECT_EQ(init_cell(p, "w").get<std::uint16_t>(), 65535);
  EXPECT_EQ(init_cell(p, "lw").get<std::uint64_t>(), UINT64_MAX);
  EXPECT_FLOAT_EQ(init_cell(p, "r").get<float>(), 1500.0f);
  EXPECT_DOUBLE_EQ(init_cell(p, "lr").get<double>(), -0.25);
  EXPECT_EQ(init_cell(p, "t").get<std::int64_t>(), 90'000'000'000);
  EXPECT_EQ(init_cell(p, "t2").get<std::int64_t>(), 1'500'000'000);
}

TEST(LoadOk, RealTagsTakeEveryFiniteFloat) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: top, type: REAL, init: 3.4028235e38}
  - {name: low, type: REAL, init: -3.4028235e38}
  - {name: tiny, type: REAL, init: 1e-45}
  - {name: conv, type: REAL, unit: m, init: 4e38 mm}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(init_cell(*r.program, "top").get<float>(), std::numeric_limits<float>::max());
  EXPECT_EQ(init_cell(*r.program, "low").get<float>(), -std::numeric_limits<float>::max());
  EXPECT_GT(init_cell(*r.program, "tiny").get<float>(), 0.0f);
  EXPECT_FLOAT_EQ(init_cell(*r.program, "conv").get<float>(), 4e35f);
}

TEST(LoadOk, ValuesWithUnitsAreConverted) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: v, type: LREAL, unit: m/s, init: 3000 mm/min}
  - {name: angle, type: LREAL, unit: rad, init: 180 deg}
  - {name: gain, type: REAL, unit: (rad/s)/PWM, init: 60 rev/min/PWM}
  - {name: plain, type: LREAL, unit: m/s, init: 2}
  - {name: pct, type: LREAL, init: 50 %}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  EXPECT_NEAR(init_cell(p, "v").get<double>(), 0.05, 1e-15);
  EXPECT_NEAR(init_cell(p, "angle").get<double>(), 3.141592653589793, 1e-15);
  EXPECT_NEAR(init_cell(p, "gain").get<float>(), 6.2831853f, 1e-6);
  EXPECT_DOUBLE_EQ(init_cell(p, "plain").get<double>(), 2.0);  // no unit: taken in the tag's unit
  EXPECT_DOUBLE_EQ(init_cell(p, "pct").get<double>(), 0.5);
}

TEST(LoadOk, AddressesThatTouchButDoNotOverlap) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: w1, type: INT, address: "%MW1"}
  - {name: d1, type: DINT, address: "%MD1"}
  - {name: l1, type: LREAL, address: "%ML1"}
  - {name: i0, type: BOOL, address: "%IX0.0"}
  - {name: i1, type: BOOL, address: "%I0.1"}
  - {name: q0, type: BOOL, address: "%QX0.0"}
  - {name: ib, type: BYTE, address: "%IB1"}
  - {name: arr, type: "ARRAY[0..1] OF WORD", address: "%IW1"}
)");
  ASSERT_LOADS(r);  // %MW1 = bytes 2-3, %MD1 = bytes 4-7, %ML1 = bytes 8-15; I and Q are separate areas
  EXPECT_EQ(r.program->find_tag("i1")->address->text(), "%IX0.1");
}

TEST(LoadOk, SafeValuesGoToTheOwnerAndToOutputDriversElsewhere) {
  auto r = load(R"(
tasks: [{name: fast, period: 1ms}, {name: slow, period: 10ms}]
tags:
  - {name: motor, type: BOOL, safe: FALSE, init: TRUE}
  - {name: speeds, type: "ARRAY[0..1] OF LREAL", unit: m/s, safe: [0, 100 mm/s]}
blocks:
  - {name: n, type: NOT, task: slow, inputs: {IN: FALSE}}
connections: [n.OUT -> motor]
drivers:
  - {name: io, type: memory, task: fast, channels: [{name: m, dir: out, type: BOOL}], bind: {m: motor}}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  const Tag* motor = p.find_tag("motor");
  EXPECT_EQ(motor->owner, 1);
  ASSERT_EQ(motor->safe.size(), 1u);
  // slow owns motor (and, being first reader-less, speeds goes to task 0).
  const auto& slow = p.tasks[1]->safe_values;
  ASSERT_EQ(slow.size(), 1u);
  EXPECT_EQ(slow[0].first, motor->cell);
  // fast drives motor through io: its local copy also gets the safe value.
  const auto& fast = p.tasks[0]->safe_values;
  ASSERT_EQ(fast.size(), 3u);
  const Tag* speeds = p.find_tag("speeds");
  EXPECT_EQ(speeds->owner, 0);
  EXPECT_DOUBLE_EQ(speeds->safe[1].get<double>(), 0.1);
}

// --- --set overrides and seeds ---------------------------------------------------------------

TEST(LoadOk, OverrideChangesTheLoadedParameter) {
  const char* text = R"(
tasks: [{name: main, period: 1ms}]
tags: [{name: lamp, type: BOOL}]
blocks: [{name: g, type: GAIN, inputs: {IN: 1}, params: {K: 2}}]
)";
  LoadOptions o;
  o.blocks = &param_blocks();
  auto plain = load(text, o);
  ASSERT_LOADS(plain);
  EXPECT_DOUBLE_EQ(gain_k(*plain.program, "g"), 2.0);

  ParamOverride ov;
  ASSERT_TRUE(parse_override("g.K=3000 mm/min", ov));
  EXPECT_EQ(ov.instance, "g");
  EXPECT_EQ(ov.param, "K");
  ParamOverride tag;
  ASSERT_TRUE(parse_override("lamp=TRUE", tag));
  EXPECT_EQ(tag.instance, "lamp");
  EXPECT_EQ(tag.param, "");
  o.overrides = {ov, tag};
  auto changed = load(text, o);
  ASSERT_LOADS(changed);
  EXPECT_DOUBLE_EQ(gain_k(*changed.program, "g"), 0.05);
  EXPECT_TRUE(init_cell(*changed.program, "lamp").get<bool>());
}

TEST(LoadOk, ParseOverrideRejectsMalformedText) {
  ParamOverride o;
  EXPECT_FALSE(parse_override("g.K", o));
  EXPECT_FALSE(parse_override("=3", o));
  EXPECT_FALSE(parse_override("g.=3", o));
  EXPECT_FALSE(parse_override("g.K=", o));
}

TEST(LoadOk, ParameterDefaultsAndUnits) {
  LoadOptions o;
  o.blocks = &param_blocks();
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
blocks:
  - {name: g1, type: GAIN, inputs: {IN: 1}}
  - {name: g2, type: GAIN, inputs: {IN: 1}, params: {K: 36 km/h}}
  - {name: k, type: NEED, params: {P: 7}}
)",
                o);
  ASSERT_LOADS(r);
  EXPECT_DOUBLE_EQ(gain_k(*r.program, "g1"), 1.0);
  EXPECT_DOUBLE_EQ(gain_k(*r.program, "g2"), 10.0);
}

TEST(LoadOk, SeedFromProjectOrOptions) {
  const char* text = R"(
project: {name: seeded, version: 2, description: any text, seed: 42}
tasks: [{name: main, period: 1ms}]
)";
  auto a = load(text);
  ASSERT_LOADS(a);
  EXPECT_EQ(a.program->seed, 42u);
  EXPECT_EQ(a.program->version, "2");
  LoadOptions o;
  o.seed = 7;
  auto b = load(text, o);
  ASSERT_LOADS(b);
  EXPECT_EQ(b.program->seed, 7u);
  EXPECT_EQ(load("tasks: [{name: main, period: 1ms}]\n").program->seed, 1u);
}

TEST(LoadOk, FailedLoadReturnsNoProgram) {
  auto r = load("tasks: [{name: main, period: 1ms}]\ntags: [{name: x, type: BOOL, init: maybe}]\n");
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.program, nullptr);
  EXPECT_EQ(r.diagnostics.size(), 1u);
  // Also when the only errors are found while building (a loop, a trace).
  auto loop = load(R"(
tasks: [{name: main, period: 1ms}]
blocks: [{name: a, type: NOT}, {name: b, type: NOT}]
connections: [a.OUT -> b.IN, b.OUT -> a.IN]
)");
  EXPECT_FALSE(loop.ok());
  EXPECT_EQ(loop.program, nullptr);
  auto trace = load("tasks: [{name: main, period: 1ms}]\ntraces: [nothing]\n");
  EXPECT_FALSE(trace.ok());
  EXPECT_EQ(trace.program, nullptr);
}

}  // namespace
}  // namespace syncplc::loadertest
