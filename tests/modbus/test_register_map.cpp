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
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  std::vector<std::string> notes;
  auto m = ModbusMap::build(*p, &notes);
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
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  auto m = ModbusMap::build(*p);
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
  auto p = load_test_project(kProject);
  ASSERT_TRUE(p);
  std::ostringstream os;
  print_modbus_map(os, *p, ModbusMap::build(*p), WordOrder::HighFirst);
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  coils 14..23  lamps BOOL[10] at %QX1.6  read/write\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  holding registers 4112..4115  big LREAL at %ML4  read/write\n"));
  EXPECT_THAT(os.str(), ::testing::HasSubstr("  input register 5  level INT at %IW5  read only\n"));
}

}  // namespace
}  // namespace syncplc
