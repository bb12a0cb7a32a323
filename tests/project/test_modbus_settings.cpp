// The project file's Modbus keys: the `modbus:` section (server settings,
// Program::modbus) and a tag's `modbus: {table, address}` (Tag::modbus),
// with every error at its exact place.
#include "tests/project/loader_test_util.hpp"

namespace syncplc::loadertest {
namespace {

using ::testing::ElementsAre;

// --- the modbus: section ---------------------------------------------------------------

TEST(ModbusSection, AbsentSectionMeansNoServer) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
)");
  ASSERT_LOADS(r);
  EXPECT_FALSE(r.modbus.server.enabled);
  EXPECT_FALSE(r.modbus.server.declared);
}

TEST(ModbusSection, PresentSectionTurnsTheServerOnWithTheDefaults) {
  for (const char* text : {"tasks: [{name: main, period: 1ms}]\nmodbus: {}\n", "tasks: [{name: main, period: 1ms}]\nmodbus:\n"}) {
    auto r = load(text);
    ASSERT_LOADS(r);
    const ModbusConfig& c = r.modbus.server;
    EXPECT_TRUE(c.enabled) << text;
    EXPECT_TRUE(c.declared);
    EXPECT_EQ(c.port, 5020);
    EXPECT_EQ(c.bind, "127.0.0.1");
    EXPECT_EQ(c.unit_id, 1);
    EXPECT_EQ(c.max_clients, 64);
    EXPECT_EQ(c.idle_timeout_ns, 60'000'000'000);
    EXPECT_EQ(c.word_order, WordOrder::HighFirst);
    EXPECT_TRUE(c.allowed_clients.empty());
    EXPECT_FALSE(c.read_only);
  }
}

TEST(ModbusSection, EveryKey) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
modbus:
  enabled: false
  port: 0
  bind: 0.0.0.0
  unit_id: 247
  max_clients: 4096
  idle_timeout: 500ms
  word_order: low_first
  allowed_clients: [10.0.0.0/8, 192.168.1.5, 0.0.0.0/0]
  read_only: true
)");
  ASSERT_LOADS(r);
  const ModbusConfig& c = r.modbus.server;
  EXPECT_FALSE(c.enabled);
  EXPECT_TRUE(c.declared);
  EXPECT_EQ(c.port, 0);
  EXPECT_EQ(c.bind, "0.0.0.0");
  EXPECT_EQ(c.unit_id, 247);
  EXPECT_EQ(c.max_clients, 4096);
  EXPECT_EQ(c.idle_timeout_ns, 500'000'000);
  EXPECT_EQ(c.word_order, WordOrder::LowFirst);
  ASSERT_EQ(c.allowed_clients.size(), 3u);
  EXPECT_EQ(c.allowed_clients[0].address, 0x0A000000u);
  EXPECT_EQ(c.allowed_clients[0].prefix, 8);
  EXPECT_EQ(c.allowed_clients[1].address, 0xC0A80105u);
  EXPECT_EQ(c.allowed_clients[1].prefix, 32);
  EXPECT_EQ(c.allowed_clients[2].prefix, 0);
  EXPECT_TRUE(c.read_only);
}

TEST(ModbusSection, LowestAndHighestValues) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
modbus: {port: 65535, unit_id: 1, max_clients: 1, idle_timeout: 0, word_order: high_first, enabled: yes}
)");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.modbus.server.port, 65535);
  EXPECT_EQ(r.modbus.server.unit_id, 1);
  EXPECT_EQ(r.modbus.server.max_clients, 1);
  EXPECT_EQ(r.modbus.server.idle_timeout_ns, 0) << "0 needs no unit: never";
  EXPECT_TRUE(r.modbus.server.enabled);
  auto s = load(R"(
tasks: [{name: main, period: 1ms}]
modbus: {idle_timeout: 0s}
)");
  ASSERT_LOADS(s);
  EXPECT_EQ(s.modbus.server.idle_timeout_ns, 0);
}

TEST(ModbusSection, EveryBadValueIsReportedAtItsPlace) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
modbus:
  enabled: maybe
  port: 70000
  bind: 1.2.3
  unit_id: 0
  max_clients: 4097
  idle_timeout: -1s
  word_order: big
  allowed_clients: [10.0.0.0/33, 1.2.3.4, nope]
  read_only: sometimes
  colour: red
  cpus: [0, 1024]
)"),
              ElementsAre("p.yaml:3:12: modbus enabled: 'maybe' is not a BOOL (TRUE or FALSE)",
                          "p.yaml:4:9: modbus port must be an integer 0..65535, not '70000'",
                          "p.yaml:5:9: modbus bind: '1.2.3' is not an IPv4 address (write e.g. 127.0.0.1, or 0.0.0.0 for every interface)",
                          "p.yaml:6:12: modbus unit_id must be an integer 1..247, not '0'",
                          "p.yaml:7:16: modbus max_clients must be an integer 1..4096, not '4097'",
                          "p.yaml:8:17: modbus idle_timeout -1s is negative (0 means never)",
                          "p.yaml:9:15: modbus word_order must be high_first or low_first, not 'big'",
                          "p.yaml:10:21: modbus allowed_clients: '10.0.0.0/33' is not an IPv4 address or network (a.b.c.d or a.b.c.d/n, n 0..32)",
                          "p.yaml:10:43: modbus allowed_clients: 'nope' is not an IPv4 address or network (a.b.c.d or a.b.c.d/n, n 0..32)",
                          "p.yaml:11:14: modbus read_only: 'sometimes' is not a BOOL (TRUE or FALSE)",
                          "p.yaml:12:11: unknown key 'colour' in modbus (enabled, port, bind, unit_id, max_clients, idle_timeout, "
                          "word_order, allowed_clients, read_only, cpus, task_status, store_status)",
                          "p.yaml:13:13: modbus cpus must be an integer 0..1023, not '1024'"));
}

TEST(ModbusSection, CpusAreOneNumberOrAList) {
  auto r = load("tasks: [{name: main, period: 1ms}]\nmodbus: {cpus: [0, 3]}\n");
  ASSERT_LOADS(r);
  EXPECT_EQ(r.modbus.server.cpus, (std::vector<int>{0, 3}));
  auto one = load("tasks: [{name: main, period: 1ms}]\nmodbus: {cpus: 2}\n");
  ASSERT_LOADS(one);
  EXPECT_EQ(one.modbus.server.cpus, (std::vector<int>{2}));
  EXPECT_THAT(errors("tasks: [{name: main, period: 1ms}]\nmodbus: {cpus: []}\n"),
              ElementsAre("p.yaml:2:16: modbus cpus: expected a CPU number or a non-empty list of them, e.g. [0, 1]"));
}

TEST(ModbusSection, MoreBadValues) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
modbus:
  port: -1
  unit_id: 248
  max_clients: 0
  idle_timeout: 5q
  bind: localhost
  allowed_clients: 10.0.0.1
)"),
              ElementsAre("p.yaml:3:9: modbus port must be an integer 0..65535, not '-1'",
                          "p.yaml:4:12: modbus unit_id must be an integer 1..247, not '248'",
                          "p.yaml:5:16: modbus max_clients must be an integer 1..4096, not '0'",
                          "p.yaml:6:17: modbus idle_timeout: '5q' is not a duration (unknown unit 'q'; write e.g. 1ms, 250us, 0.5s, T#1m30s)",
                          "p.yaml:7:9: modbus bind: 'localhost' is not an IPv4 address (write e.g. 127.0.0.1, or 0.0.0.0 for every interface)",
                          "p.yaml:8:20: modbus allowed_clients: expected a list of a.b.c.d or a.b.c.d/n"));
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
modbus: {port: 50.5, allowed_clients: []}
)"),
              ElementsAre("p.yaml:2:16: modbus port must be an integer 0..65535, not '50.5'",
                          "p.yaml:2:39: modbus allowed_clients: the list is empty (leave the key out to let any client in)"));
}

TEST(ModbusSection, MustBeAMap) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
modbus: [5020]
)"),
              ElementsAre("p.yaml:2:9: modbus: expected a map {enabled, port, bind, unit_id, max_clients, idle_timeout, "
                          "word_order, allowed_clients, read_only, cpus, task_status, store_status}"));
}

TEST(ModbusSection, ComesFromAnIncludedFileOrFromOneFileOnly) {
  std::string main = temp_file("modbus/main.yaml", yaml(R"(
include: [sub.yaml]
tasks: [{name: main, period: 1ms}]
)"));
  std::string sub = temp_file("modbus/sub.yaml", yaml(R"(
modbus: {port: 1502}
)"));
  auto r = load_project(main);
  ASSERT_LOADS(r);
  EXPECT_TRUE(r.modbus.server.enabled);
  EXPECT_EQ(r.modbus.server.port, 1502);
  std::string twice = temp_file("modbus/twice.yaml", yaml(R"(
include: [sub.yaml]
tasks: [{name: main, period: 1ms}]
modbus: {port: 502}
)"));
  EXPECT_THAT(errors(load_project(twice)),
              ElementsAre(sub + ":1:9: 'modbus' is also set at " + twice +
                          ":3:9: a map section may come from one file only"));
}

// --- a tag's modbus: {table, address} -----------------------------------------------------

TEST(ModbusPlaces, ATagMayHaveAPlaceWithoutADirectAddress) {
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, hmi: readwrite, modbus: {table: holding_register, address: 3000}}
  - {name: level, type: INT, address: "%MW4", hmi: read, modbus: {table: input_register, address: 0}}
  - {name: lamps, type: "ARRAY[1..16] OF BOOL", hmi: read, modbus: {table: coil, address: 65520}}
  - {name: ready, type: BOOL, hmi: read, modbus: {address: 16#10, table: discrete_input}}
  - {name: plain, type: INT, address: "%MW5", hmi: read}
)");
  ASSERT_LOADS(r);
  const Program& p = *r.program;
  auto place = [&](const std::string& tag) { return explicit_place(r.modbus.places, p.find_tag(tag) - p.tags.data()); };
  ASSERT_TRUE(place("speed"));
  EXPECT_EQ(place("speed")->table, ModbusTable::HoldingRegisters);
  EXPECT_EQ(place("speed")->address, 3000u);
  EXPECT_FALSE(p.find_tag("speed")->address);
  EXPECT_EQ(place("level")->table, ModbusTable::InputRegisters);
  EXPECT_EQ(place("lamps")->address, 65520u) << "16 coils up to 65535";
  EXPECT_EQ(place("ready")->address, 16u);
  EXPECT_FALSE(place("plain"));
}

TEST(ModbusPlaces, TheTagNeedsHmiAccess) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, modbus: {table: holding_register, address: 3000}}
  - {name: other, type: LREAL, hmi: none, modbus: {table: holding_register, address: 3000}}
)"),
              ElementsAre("p.yaml:3:40: tag speed has a Modbus place but hmi none: give it hmi: read or readwrite",
                          "p.yaml:4:51: tag other has a Modbus place but hmi none: give it hmi: read or readwrite"));
}

TEST(ModbusPlaces, BoolsAreCoilsOrDiscreteInputsEverythingElseRegisters) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: lamp, type: BOOL, hmi: read, modbus: {table: holding_register, address: 1}}
  - {name: count, type: INT, hmi: read, modbus: {table: coil, address: 1}}
  - {name: flags, type: "ARRAY[0..1] OF WORD", hmi: read, modbus: {table: discrete_input, address: 1}}
  - {name: bits, type: "ARRAY[0..1] OF BOOL", hmi: read, modbus: {table: input_register, address: 1}}
)"),
              ElementsAre("p.yaml:3:57: tag lamp is BOOL: its Modbus table must be coil or discrete_input, not holding_register",
                          "p.yaml:4:57: tag count is INT: its Modbus table must be input_register or holding_register, not coil",
                          "p.yaml:5:75: tag flags is WORD: its Modbus table must be input_register or holding_register, not discrete_input",
                          "p.yaml:6:74: tag bits is BOOL: its Modbus table must be coil or discrete_input, not input_register"));
}

TEST(ModbusPlaces, ThePlaceMustEndBy65535) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, hmi: read, modbus: {table: holding_register, address: 65533}}
  - {name: pos, type: "ARRAY[1..3] OF DINT", hmi: read, modbus: {table: input_register, address: 65531}}
  - {name: lamps, type: "ARRAY[0..1] OF BOOL", hmi: read, modbus: {table: coil, address: 65535}}
  - {name: fits, type: "ARRAY[1..3] OF DINT", hmi: read, modbus: {table: input_register, address: 65530}}
)"),
              ElementsAre("p.yaml:3:86: modbus place of speed: holding registers 65533..65536 run past 65535",
                          "p.yaml:4:98: modbus place of pos: input registers 65531..65536 run past 65535",
                          "p.yaml:5:90: modbus place of lamps: coils 65535..65536 run past 65535"));
}

TEST(ModbusPlaces, TableAndAddressAreChecked) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: INT, hmi: read, modbus: {table: holding, address: 1}}
  - {name: b, type: INT, hmi: read, modbus: {table: input_register, address: 65536}}
  - {name: c, type: INT, hmi: read, modbus: {table: input_register, address: -1}}
  - {name: d, type: INT, hmi: read, modbus: {table: input_register, address: x}}
  - {name: e, type: INT, hmi: read, modbus: {address: 1}}
  - {name: f, type: INT, hmi: read, modbus: {table: coil}}
  - {name: g, type: INT, hmi: read, modbus: {table: input_register, address: 1, size: 2}}
  - {name: h, type: INT, hmi: read, modbus: 3000}
  - {name: i, type: INT, hmi: read, mudbus: 3000}
)"),
              ElementsAre("p.yaml:3:53: modbus table must be coil, discrete_input, input_register or holding_register, not 'holding'",
                          "p.yaml:4:78: modbus address must be an integer 0..65535, not '65536'",
                          "p.yaml:5:78: modbus address must be an integer 0..65535, not '-1'",
                          "p.yaml:6:78: modbus address must be an integer 0..65535, not 'x'",
                          "p.yaml:7:45: modbus of e has no table (coil, discrete_input, input_register, holding_register)",
                          "p.yaml:8:45: modbus of f has no address",
                          "p.yaml:8:53: tag f is INT: its Modbus table must be input_register or holding_register, not coil",
                          "p.yaml:9:87: unknown key 'size' in a tag's modbus (table, address)",
                          "p.yaml:10:45: modbus of h: expected a map {table, address}",
                          "p.yaml:11:45: unknown key 'mudbus' in a tag (name, type, address, modbus, retain, persistent, trend, hmi, unit, "
                          "description, init, safe, min, max, task)"));
}

TEST(ModbusPlaces, TwoExplicitPlacesMayNotOverlap) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: LREAL, hmi: read, modbus: {table: holding_register, address: 3000}}
  - {name: b, type: DINT, hmi: read, modbus: {table: holding_register, address: 3003}}
  - {name: c, type: DINT, hmi: read, modbus: {table: input_register, address: 3003}}
  - {name: d, type: "ARRAY[1..2] OF BOOL", hmi: read, modbus: {table: coil, address: 7}}
  - {name: e, type: BOOL, hmi: read, modbus: {table: coil, address: 8}}
)"),
              ElementsAre("p.yaml:4:46: modbus place of b (holding registers 3003..3004) overlaps a (holding registers "
                          "3000..3003, defined at p.yaml:3:5)",
                          "p.yaml:7:46: modbus place of e (coil 8) overlaps d (coils 7..8, defined at p.yaml:6:5)"));
}

TEST(ModbusPlaces, AnExplicitPlaceMayNotOverlapAConventionPlace) {
  // %MW0 is holding register 1024 and %QX0.1 coil 1 by the convention; the
  // error is at the explicit place, whichever tag comes first.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: conv, type: INT, address: "%MW0", hmi: read}
  - {name: expl, type: DINT, hmi: read, modbus: {table: holding_register, address: 1023}}
  - {name: coil_e, type: BOOL, hmi: read, modbus: {table: coil, address: 1}}
  - {name: coil_c, type: BOOL, address: "%QX0.1", hmi: read}
  - {name: quiet, type: INT, address: "%MW1", modbus: {table: input_register, address: 0}}
)"),
              ElementsAre("p.yaml:4:49: modbus place of expl (holding registers 1023..1024) overlaps conv (holding "
                          "register 1024 by %MW0, defined at p.yaml:3:5)",
                          "p.yaml:5:51: modbus place of coil_e (coil 1) overlaps coil_c (coil 1 by %QX0.1, defined at p.yaml:6:5)",
                          "p.yaml:7:55: tag quiet has a Modbus place but hmi none: give it hmi: read or readwrite"));
}

TEST(ModbusPlaces, AnExplicitPlaceReplacesTheConventionsSoItFreesThatPlace) {
  // moved's own convention place (holding 1024) is not taken: b may use it.
  auto r = load(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: moved, type: INT, address: "%MW0", hmi: read, modbus: {table: input_register, address: 0}}
  - {name: b, type: INT, hmi: read, modbus: {table: holding_register, address: 1024}}
)");
  ASSERT_LOADS(r);
}

TEST(ModbusPlaces, AWrongPlaceCausesNoOverlapError) {
  // b's place is refused (an INT among the coils), so it does not also
  // overlap a, nor falls back to the convention's holding register 1024.
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: a, type: INT, hmi: read, modbus: {table: holding_register, address: 1024}}
  - {name: b, type: INT, address: "%MW0", hmi: read, modbus: {table: coil, address: 0}}
)"),
              ElementsAre("p.yaml:4:70: tag b is INT: its Modbus table must be input_register or holding_register, not coil"));
}

TEST(ModbusPlaces, OverlappingDirectAddressesAreReportedOnceAtTheAddress) {
  EXPECT_THAT(errors(R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: q1, type: BOOL, address: "%QX1.1", hmi: read}
  - {name: q2, type: BOOL, address: "%QX1.1", hmi: read}
)"),
              ElementsAre("p.yaml:4:37: address %QX1.1 of q2 overlaps %QX1.1 of q1 (defined at p.yaml:3:5)"));
}

}  // namespace
}  // namespace syncplc::loadertest
