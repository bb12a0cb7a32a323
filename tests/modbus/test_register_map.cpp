// The Modbus address map (OpenPLC convention) and the register encoding of
// 16/32/64-bit values in both word orders.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <sstream>

#include "runtime/modbus/register_map.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

const char* kProject = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: start, type: BOOL, address: "%IX0.3", hmi: read}
  - {name: lamps, type: "ARRAY[0..9] OF BOOL", address: "%QX1.6", hmi: readwrite}
  - {name: level, type: INT, address: "%IW5", hmi: read}
  - {name: speed_sp, type: UINT, address: "%QW2", hmi: readwrite}
  - {name: counts, type: "ARRAY[1..3] OF WORD", address: "%MW10", hmi: read}
  - {name: pos, type: REAL, address: "%MD3", hmi: readwrite}
  - {name: big, type: LREAL, address: "%ML4", hmi: readwrite}
  - {name: dint, type: DINT, address: "%MD4", hmi: read}
  - {name: hidden, type: INT, address: "%MW0"}
  - {name: bytes, type: BYTE, address: "%IB2", hmi: read}
  - {name: far, type: WORD, address: "%IW1024", hmi: read}
)";

TEST(ModbusMap, FollowsTheOpenPlcConvention) {
  auto r = load_test_result(kProject);
  auto& p = r.program;
  ASSERT_TRUE(p);
  std::vector<std::string> notes;
  auto m = ModbusMap::build(*p, r.modbus, &notes);
  auto tag_of = [&](const ModbusPoint* pt) { return pt ? p->tags[pt->tag].name : std::string("-"); };
  // %IX0.3 -> discrete input 3; %QX1.6 .. -> coils 14..23
  EXPECT_EQ(tag_of(m.at(ModbusTable::DiscreteInputs, 3)), "start");
  EXPECT_EQ(m.at(ModbusTable::DiscreteInputs, 2), nullptr);
  EXPECT_EQ(tag_of(m.at(ModbusTable::Coils, 14)), "lamps");
  EXPECT_EQ(m.at(ModbusTable::Coils, 23)->element, 9u);
  EXPECT_EQ(m.at(ModbusTable::Coils, 24), nullptr);
  EXPECT_TRUE(m.at(ModbusTable::Coils, 14)->writable);
  // %IW5 -> input register 5; %QW2 -> holding 2; %MW10.. -> holding 1034..1036
  EXPECT_EQ(tag_of(m.at(ModbusTable::InputRegisters, 5)), "level");
  EXPECT_FALSE(m.at(ModbusTable::InputRegisters, 5)->writable);
  EXPECT_EQ(tag_of(m.at(ModbusTable::HoldingRegisters, 2)), "speed_sp");
  EXPECT_EQ(tag_of(m.at(ModbusTable::HoldingRegisters, 1036)), "counts");
  EXPECT_FALSE(m.at(ModbusTable::HoldingRegisters, 1034)->writable) << "hmi: read";
  // %MD3 -> holding 2054, 2055; %MD4 -> 2056, 2057; %ML4 -> 4112..4115
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 2055)->address, 2054u);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 2055)->width, 2u);
  EXPECT_EQ(tag_of(m.at(ModbusTable::HoldingRegisters, 2056)), "dint");
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 4115)->address, 4112u);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 4115)->width, 4u);
  // No HMI access, a byte address and one beyond the range: not mapped.
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 1024), nullptr);
  EXPECT_THAT(notes, ::testing::ElementsAre(::testing::HasSubstr("bytes at %IB2: no Modbus place"),
                                            ::testing::HasSubstr("far at %IW1024: beyond the input register range")));
}

TEST(ModbusMap, RangesMustBeMappedAndMustNotCutAValue) {
  auto loaded = load_test_result(kProject);
  ASSERT_TRUE(loaded.program);
  auto m = ModbusMap::build(*loaded.program, loaded.modbus);
  auto r = m.range(ModbusTable::HoldingRegisters, 2054, 4);  // pos and dint whole
  ASSERT_TRUE(r);
  EXPECT_EQ(r->size(), 2u);
  EXPECT_FALSE(m.range(ModbusTable::HoldingRegisters, 2055, 2)) << "starts inside pos";
  EXPECT_FALSE(m.range(ModbusTable::HoldingRegisters, 2054, 3)) << "ends inside dint";
  EXPECT_FALSE(m.range(ModbusTable::HoldingRegisters, 1033, 2)) << "1033 is unmapped";
  EXPECT_TRUE(m.range(ModbusTable::HoldingRegisters, 1034, 3));
  EXPECT_FALSE(m.range(ModbusTable::HoldingRegisters, 0xFFFFFFFFu, 2)) << "no wrap-around";
  EXPECT_FALSE(m.range(ModbusTable::Coils, 14, 0));
  EXPECT_EQ(m.range(ModbusTable::Coils, 14, 10)->size(), 10u);
}

// Explicit places (`modbus: {table, address}`) beside the convention's.
const char* kExplicit = R"(
tasks: [{name: main, period: 1ms}]
tags:
  - {name: speed, type: LREAL, hmi: readwrite, modbus: {table: holding_register, address: 3000}}
  - {name: moved, type: INT, address: "%MW0", hmi: readwrite, modbus: {table: input_register, address: 7}}
  - {name: flags, type: "ARRAY[1..3] OF BOOL", hmi: readwrite, modbus: {table: discrete_input, address: 100}}
  - {name: coil_cmd, type: BOOL, hmi: readwrite, modbus: {table: coil, address: 9000}}
  - {name: levels, type: "ARRAY[0..1] OF REAL", hmi: read, modbus: {table: holding_register, address: 65532}}
  - {name: plain, type: INT, address: "%MW1", hmi: read}
)";

TEST(ModbusMap, ExplicitPlacesTakePrecedenceOverTheConvention) {
  auto r = load_test_result(kExplicit);
  auto& p = r.program;
  ASSERT_TRUE(p);
  auto m = ModbusMap::build(*p, r.modbus);
  auto tag_of = [&](const ModbusPoint* pt) { return pt ? p->tags[pt->tag].name : std::string("-"); };
  EXPECT_EQ(tag_of(m.at(ModbusTable::HoldingRegisters, 3003)), "speed");
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 3003)->address, 3000u);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 3003)->width, 4u);
  // %MW0 would be holding 1024: the explicit input register 7 replaces it.
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 1024), nullptr);
  EXPECT_EQ(tag_of(m.at(ModbusTable::InputRegisters, 7)), "moved");
  EXPECT_EQ(tag_of(m.at(ModbusTable::HoldingRegisters, 1025)), "plain");
  EXPECT_EQ(m.at(ModbusTable::DiscreteInputs, 102)->element, 2u);
  EXPECT_EQ(m.at(ModbusTable::DiscreteInputs, 103), nullptr);
  EXPECT_EQ(tag_of(m.at(ModbusTable::Coils, 9000)), "coil_cmd");
  // Two REALs up to the last register of the table.
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 65535)->address, 65534u);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 65535)->element, 1u);
  EXPECT_TRUE(m.range(ModbusTable::HoldingRegisters, 65532, 4));
  EXPECT_EQ(m.range(ModbusTable::HoldingRegisters, 3000, 4)->size(), 1u);
  EXPECT_FALSE(m.range(ModbusTable::HoldingRegisters, 3000, 2)) << "cuts speed";
}

TEST(ModbusMap, ExplicitPlacesAreWritableOnlyInCoilsAndHoldingRegistersWithReadwrite) {
  auto r = load_test_result(kExplicit);
  auto& p = r.program;
  ASSERT_TRUE(p);
  auto m = ModbusMap::build(*p, r.modbus);
  EXPECT_TRUE(m.at(ModbusTable::HoldingRegisters, 3000)->writable);
  EXPECT_TRUE(m.at(ModbusTable::Coils, 9000)->writable);
  EXPECT_FALSE(m.at(ModbusTable::InputRegisters, 7)->writable) << "input registers are read only";
  EXPECT_FALSE(m.at(ModbusTable::DiscreteInputs, 100)->writable) << "discrete inputs are read only";
  EXPECT_FALSE(m.at(ModbusTable::HoldingRegisters, 65532)->writable) << "hmi: read";
}

// Programs built by hand: the map's own overlap rule, without the loader's checks.
struct HandMadeTag {
  Tag tag;
  std::optional<ModbusPlace> place;
};
HandMadeTag modbus_tag(const std::string& name, IecType type, std::uint32_t length, std::optional<ModbusPlace> place,
                       const char* address = nullptr) {
  Tag t;
  t.name = name;
  t.type = type;
  t.length = length;
  t.hmi = HmiAccess::ReadWrite;
  if (address) t.address = *parse_direct_address(address, nullptr);
  return {t, place};
}
struct HandMadeTags {
  std::vector<Tag> tags;
  ModbusPlaces places;
};
HandMadeTags hand_made(std::initializer_list<HandMadeTag> list) {
  HandMadeTags h;
  for (const auto& t : list) {
    h.tags.push_back(t.tag);
    h.places.push_back(t.place);
  }
  return h;
}

TEST(ModbusMap, OverlapsLeaveTheLaterTagOutAndAreReported) {
  auto [tags, places] = hand_made({
      modbus_tag("a", IecType::LREAL, 1, ModbusPlace{ModbusTable::HoldingRegisters, 3000}),
      modbus_tag("b", IecType::DINT, 1, ModbusPlace{ModbusTable::HoldingRegisters, 3003}),   // into a's last register
      modbus_tag("c", IecType::INT, 2, ModbusPlace{ModbusTable::HoldingRegisters, 2998}),    // 2998..2999: just before a
      modbus_tag("d", IecType::INT, 1, ModbusPlace{ModbusTable::InputRegisters, 3000}),      // another table
  });
  std::vector<ModbusOverlap> overlaps;
  auto m = ModbusMap::build(tags, places, nullptr, &overlaps);
  ASSERT_EQ(overlaps.size(), 1u);
  EXPECT_EQ(overlaps[0].tag, 1u);
  EXPECT_EQ(overlaps[0].other, 0u);
  EXPECT_EQ(modbus_span_text(overlaps[0].span), "holding registers 3003..3004");
  EXPECT_EQ(modbus_span_text(overlaps[0].other_span), "holding registers 3000..3003");
  EXPECT_TRUE(overlaps[0].span.explicit_place);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 3004), nullptr) << "b is left out";
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 3003)->tag, 0u);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 2999)->tag, 2u);
  EXPECT_EQ(m.at(ModbusTable::InputRegisters, 3000)->tag, 3u);
  // Sorted and free of overlaps.
  const auto& v = m.points(ModbusTable::HoldingRegisters);
  for (std::size_t i = 1; i < v.size(); ++i) EXPECT_GE(v[i].address, v[i - 1].address + v[i - 1].width);
}

TEST(ModbusMap, AnExplicitPlaceWinsOverAConventionPlaceDeclaredBeforeIt) {
  auto [tags, places] = hand_made({
      modbus_tag("conv", IecType::INT, 1, std::nullopt, "%MW0"),                            // holding 1024
      modbus_tag("expl", IecType::DINT, 1, ModbusPlace{ModbusTable::HoldingRegisters, 1023}),  // 1023..1024
  });
  std::vector<ModbusOverlap> overlaps;
  auto m = ModbusMap::build(tags, places, nullptr, &overlaps);
  ASSERT_EQ(overlaps.size(), 1u);
  EXPECT_EQ(overlaps[0].tag, 0u) << "the convention's place is the one left out";
  EXPECT_EQ(overlaps[0].other, 1u);
  EXPECT_FALSE(overlaps[0].span.explicit_place);
  EXPECT_TRUE(overlaps[0].other_span.explicit_place);
  EXPECT_EQ(m.at(ModbusTable::HoldingRegisters, 1024)->tag, 1u);
}

TEST(ModbusMap, AnExplicitPlaceThatDoesNotFitIsANote) {
  auto [tags, places] = hand_made({
      modbus_tag("bit", IecType::BOOL, 1, ModbusPlace{ModbusTable::HoldingRegisters, 0}),
      modbus_tag("long", IecType::LREAL, 1, ModbusPlace{ModbusTable::HoldingRegisters, 65533}),
      modbus_tag("hidden", IecType::INT, 1, ModbusPlace{ModbusTable::HoldingRegisters, 5}),
  });
  tags[2].hmi = HmiAccess::None;
  std::vector<std::string> notes;
  auto m = ModbusMap::build(tags, places, &notes);
  EXPECT_THAT(notes, ::testing::ElementsAre("bit: a BOOL has no place among the holding registers",
                                            "long: its holding registers run past 65535"));
  EXPECT_TRUE(m.points(ModbusTable::HoldingRegisters).empty()) << "hmi none: not on Modbus";
}

TEST(ModbusEncoding, WorkedExamplesInBothWordOrders) {
  std::uint16_t r[4];
  // REAL 1.0f = 0x3F800000: high word first 3F80 0000, swapped 0000 3F80.
  Cell c;
  c.set<float>(1.0f);
  encode_registers(IecType::REAL, c, WordOrder::HighFirst, r);
  EXPECT_EQ(r[0], 0x3F80);
  EXPECT_EQ(r[1], 0x0000);
  encode_registers(IecType::REAL, c, WordOrder::LowFirst, r);
  EXPECT_EQ(r[0], 0x0000);
  EXPECT_EQ(r[1], 0x3F80);
  // LREAL 1.5 = 0x3FF8000000000000.
  c.set<double>(1.5);
  encode_registers(IecType::LREAL, c, WordOrder::HighFirst, r);
  EXPECT_THAT(r, ::testing::ElementsAre(0x3FF8, 0, 0, 0));
  encode_registers(IecType::LREAL, c, WordOrder::LowFirst, r);
  EXPECT_THAT(r, ::testing::ElementsAre(0, 0, 0, 0x3FF8));
  // DINT -2 = 0xFFFFFFFE; INT -1 = 0xFFFF; UDINT 0x12345678.
  c.set<std::int32_t>(-2);
  encode_registers(IecType::DINT, c, WordOrder::HighFirst, r);
  EXPECT_EQ(r[0], 0xFFFF);
  EXPECT_EQ(r[1], 0xFFFE);
  c.set<std::int16_t>(-1);
  encode_registers(IecType::INT, c, WordOrder::HighFirst, r);
  EXPECT_EQ(r[0], 0xFFFF);
  c.set<std::uint32_t>(0x12345678u);
  encode_registers(IecType::UDINT, c, WordOrder::LowFirst, r);
  EXPECT_EQ(r[0], 0x5678);
  EXPECT_EQ(r[1], 0x1234);
}

TEST(ModbusEncoding, EveryTypeRoundTripsInBothOrders) {
  const double samples[] = {0.0, -0.0, 1.0, -1.5, 3.141592653589793, 1e300, -1e-300, 65535.0, -32768.0};
  for (IecType t : {IecType::INT, IecType::UINT, IecType::WORD, IecType::DINT, IecType::UDINT, IecType::DWORD,
                    IecType::REAL, IecType::LINT, IecType::ULINT, IecType::LWORD, IecType::LREAL, IecType::TIME})
    for (WordOrder o : {WordOrder::HighFirst, WordOrder::LowFirst})
      for (double v : samples) {
        std::string err;
        auto c = real_cell(IecType::LREAL, v, "", &err);
        Cell x = c ? *c : Cell{};
        if (t != IecType::LREAL) x = Cell{};
        if (t == IecType::REAL) x.set<float>(static_cast<float>(v));
        if (t == IecType::LREAL) x.set<double>(v);
        if (t == IecType::DINT) x.set<std::int32_t>(static_cast<std::int32_t>(v > 2e9 || v < -2e9 ? 7 : v));
        if (t == IecType::LINT) x.set<std::int64_t>(-1234567890123LL);
        if (t == IecType::ULINT || t == IecType::LWORD) x.set<std::uint64_t>(0xFEDCBA9876543210ULL);
        std::uint16_t r[4] = {};
        encode_registers(t, x, o, r);
        Cell y = decode_registers(t, r, o);
        EXPECT_EQ(format_value(t, x), format_value(t, y)) << type_name(t);
      }
}

TEST(ModbusMap, CheckPrintsTheMap) {
  auto r = load_test_result(kProject);
  auto& p = r.program;
  ASSERT_TRUE(p);
  std::ostringstream os;
  print_modbus_map(os, *p, ModbusMap::build(*p, r.modbus), WordOrder::HighFirst);
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  coils 14..23  lamps BOOL[10] at %QX1.6  read/write\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  holding registers 4112..4115  big LREAL at %ML4  read/write\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  input register 5  level INT at %IW5  read only\n"));
}

TEST(ModbusMap, CheckMarksExplicitPlacesAndPrintsTheWordOrder) {
  auto r = load_test_result(kExplicit);
  auto& p = r.program;
  ASSERT_TRUE(p);
  std::ostringstream os;
  print_modbus_map(os, *p, ModbusMap::build(*p, r.modbus), WordOrder::LowFirst);
  EXPECT_THAT(os.str(), ::testing::HasSubstr("32/64-bit values low word first"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  holding registers 3000..3003  speed LREAL (explicit)  read/write\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  input register 7  moved INT (explicit)  read only\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  discrete inputs 100..102  flags BOOL[3] (explicit)  read only\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  holding register 1025  plain INT at %MW1  read only\n"));
}

TEST(ModbusMap, StatusBlocksOfTasksAndStoreAreListedAndKeptClearOfTags) {
  auto r = load_test_result(kProject);
  ASSERT_TRUE(r.program);
  std::ostringstream os;
  print_modbus_map(os, *r.program, ModbusMap::build(*r.program, r.modbus), WordOrder::HighFirst);
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  input registers 8990..8997  status of the store (state, s since commit, "
                                             "pending, lost, failures)  read only\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  input registers 9000..9007  status of task main"));
  ModbusSettings s = r.modbus;
  s.server.store_status = 9004;  // inside the task status block
  std::vector<std::string> notes;
  ModbusMap m = ModbusMap::build(*r.program, s, &notes);
  EXPECT_THAT(notes, ::testing::Contains("store status not served: input registers 9004..9011 overlap the task status "
                                         "block (move it with modbus: {store_status: N})"));
  for (const auto& pt : m.points(ModbusTable::InputRegisters)) EXPECT_FALSE(is_store_status(pt.status));
  s.server.store_status = 3;  // tag level is input register 5
  notes.clear();
  ModbusMap::build(*r.program, s, &notes);
  EXPECT_THAT(notes, ::testing::Contains("store status not served: input registers 3..10 overlap tag level (move it "
                                         "with modbus: {store_status: N})"));
  s.server.store_status.reset();
  m = ModbusMap::build(*r.program, s);
  for (const auto& pt : m.points(ModbusTable::InputRegisters)) EXPECT_FALSE(is_store_status(pt.status));
}

TEST(ModbusConfig, ClientNetworksParseAndPrint) {
  auto n = parse_client_network("192.168.1.0/24");
  ASSERT_TRUE(n);
  EXPECT_EQ(n->address, 0xC0A80100u);
  EXPECT_EQ(n->prefix, 24);
  EXPECT_TRUE(n->contains(0xC0A801FEu));
  EXPECT_FALSE(n->contains(0xC0A80201u));
  EXPECT_EQ(client_network_text(*n), "192.168.1.0/24");
  EXPECT_EQ(client_network_text(*parse_client_network("10.1.2.3")), "10.1.2.3");
  EXPECT_EQ(parse_client_network("0.0.0.0/0")->prefix, 0);
  for (const char* bad : {"", "10.0.0", "10.0.0.256", "10.0.0.1/33", "10.0.0.1/", "10.0.0.1/x", "10.0.0.1/-1", "host", "10.0.0.1/008"})
    EXPECT_FALSE(parse_client_network(bad)) << bad;
}

TEST(ModbusConfig, SettingsOnOneLine) {
  ModbusConfig c;
  c.enabled = true;
  EXPECT_EQ(modbus_settings_text(c),
            "127.0.0.1:5020, unit 1, max 64 clients, idle timeout 60s, high word first, read/write, clients: any");
  c.bind = "0.0.0.0";
  c.port = 0;
  c.unit_id = 17;
  c.max_clients = 1;
  c.idle_timeout_ns = 0;
  c.word_order = WordOrder::LowFirst;
  c.read_only = true;
  c.allowed_clients = {*parse_client_network("10.0.0.0/8"), *parse_client_network("192.168.1.5")};
  EXPECT_EQ(modbus_settings_text(c), "0.0.0.0:0 (any free port), unit 17, max 1 client, no idle timeout, low word first, "
                                     "read only, clients: 10.0.0.0/8, 192.168.1.5");
  c.idle_timeout_ns = 1'500'000'000;
  EXPECT_THAT(modbus_settings_text(c), ::testing::HasSubstr("idle timeout 1s500ms"));
}

}  // namespace
}  // namespace syncplc
