// The Modbus client's frames: requests byte by byte (Modbus Application
// Protocol v1.1b3 §6) and every class of bad reply (client_error.hpp), plus
// the values' encoding through the server's register codec.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "runtime/io/modbus_client/client_frame.hpp"
#include "runtime/io/modbus_client/wire_values.hpp"

namespace syncplc {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes request(const ClientRequest& r) {
  std::uint8_t b[kMaxAdu];
  return Bytes(b, b + build_request(r, b));
}

// A reply ADU: MBAP with the right length field, then the PDU.
Bytes reply(std::uint16_t tid, std::uint8_t unit, Bytes pdu) {
  Bytes b = {static_cast<std::uint8_t>(tid >> 8), static_cast<std::uint8_t>(tid), 0, 0,
             static_cast<std::uint8_t>((pdu.size() + 1) >> 8), static_cast<std::uint8_t>(pdu.size() + 1), unit};
  b.insert(b.end(), pdu.begin(), pdu.end());
  return b;
}

ClientError parse(const ClientRequest& r, const Bytes& b) { return parse_reply(r, b.data(), b.size()).error; }

ClientRequest read_holding(std::uint16_t addr, std::uint16_t n) {
  ClientRequest r;
  r.function = ModbusFunction::ReadHoldingRegisters;
  r.unit = 7;
  r.transaction = 0x1234;
  r.address = addr;
  r.quantity = n;
  return r;
}

TEST(ModbusClientFrame, RequestsAreTheStandardsBytes) {
  EXPECT_EQ(request(read_holding(0x10, 2)), (Bytes{0x12, 0x34, 0, 0, 0, 6, 7, 3, 0x00, 0x10, 0, 2}));

  ClientRequest c;
  c.function = ModbusFunction::WriteSingleCoil;
  c.transaction = 1;
  c.address = 5;
  std::uint8_t on = 1;
  c.bits = &on;
  EXPECT_EQ(request(c), (Bytes{0, 1, 0, 0, 0, 6, 1, 5, 0, 5, 0xFF, 0x00}));

  ClientRequest mc;
  mc.function = ModbusFunction::WriteMultipleCoils;
  mc.transaction = 2;
  mc.address = 19;
  mc.quantity = 10;  // §6.11's example: 10 coils CD 01
  std::uint8_t bits[10] = {1, 0, 1, 1, 0, 0, 1, 1, 1, 0};
  mc.bits = bits;
  EXPECT_EQ(request(mc), (Bytes{0, 2, 0, 0, 0, 9, 1, 15, 0, 19, 0, 10, 2, 0xCD, 0x01}));

  ClientRequest mr;
  mr.function = ModbusFunction::WriteMultipleRegisters;
  mr.transaction = 3;
  mr.address = 1;
  mr.quantity = 2;
  std::uint16_t regs[2] = {0x000A, 0x0102};
  mr.registers = regs;
  EXPECT_EQ(request(mr), (Bytes{0, 3, 0, 0, 0, 11, 1, 16, 0, 1, 0, 2, 4, 0x00, 0x0A, 0x01, 0x02}));

  ClientRequest rw;
  rw.function = ModbusFunction::ReadWriteMultipleRegisters;
  rw.transaction = 4;
  rw.address = 3;
  rw.quantity = 6;
  rw.write_address = 14;
  rw.write_quantity = 3;
  std::uint16_t w[3] = {0x00FF, 0x00FF, 0x00FF};  // §6.17's example
  rw.registers = w;
  EXPECT_EQ(request(rw), (Bytes{0, 4, 0, 0, 0, 17, 1, 23, 0, 3, 0, 6, 0, 14, 0, 3, 6, 0, 0xFF, 0, 0xFF, 0, 0xFF}));
}

TEST(ModbusClientFrame, AGoodReadReplyGivesItsData) {
  const auto r = read_holding(0, 2);
  const Bytes b = reply(0x1234, 7, {3, 4, 0x00, 0x2A, 0xFF, 0xFF});
  const ClientReply got = parse_reply(r, b.data(), b.size());
  ASSERT_EQ(got.error, ClientError::None);
  ASSERT_EQ(got.bytes, 4u);
  EXPECT_EQ(got.data[1], 0x2A);
}

TEST(ModbusClientFrame, EveryBadReplyHasItsOwnCode) {
  const auto r = read_holding(0, 2);
  const Bytes good = reply(0x1234, 7, {3, 4, 0, 1, 0, 2});
  ASSERT_EQ(parse(r, good), ClientError::None);

  EXPECT_EQ(parse(r, Bytes(good.begin(), good.begin() + 7)), ClientError::Short);  // header alone
  EXPECT_EQ(parse(r, Bytes{}), ClientError::Short);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {3, 4, 0, 1})), ClientError::Short);            // fewer data than its byte count
  EXPECT_EQ(parse(r, reply(0x1234, 7, {3})), ClientError::Short);                     // no byte count
  EXPECT_EQ(parse(r, reply(0x1234, 7, {3, 4, 0, 1, 0, 2, 9})), ClientError::Oversized);  // a byte past its byte count
  Bytes huge = good;
  huge[4] = 0x01;  // length field 0x010B: past the 260-byte ADU
  EXPECT_EQ(parse(r, huge), ClientError::Oversized);
  Bytes proto = good;
  proto[3] = 1;  // protocol id 1
  EXPECT_EQ(parse(r, proto), ClientError::Malformed);
  Bytes len = good;
  len[5] = static_cast<std::uint8_t>(len[5] + 1);  // length field one more than the frame
  EXPECT_EQ(parse(r, len), ClientError::Malformed);
  EXPECT_EQ(parse(r, reply(0x1235, 7, {3, 4, 0, 1, 0, 2})), ClientError::WrongTransaction);
  EXPECT_EQ(parse(r, reply(0x1234, 8, {3, 4, 0, 1, 0, 2})), ClientError::WrongUnit);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {4, 4, 0, 1, 0, 2})), ClientError::WrongFunction);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {0x84, 2})), ClientError::WrongFunction);  // another function's exception
  EXPECT_EQ(parse(r, reply(0x1234, 7, {3, 2, 0, 1})), ClientError::WrongByteCount);  // one register for two
  EXPECT_EQ(parse(r, reply(0x1234, 7, {0x83, 2})), exception_error(2));
  EXPECT_EQ(code(parse(r, reply(0x1234, 7, {0x83, 2}))), 2);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {0x83})), ClientError::Short);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {0x83, 2, 0})), ClientError::Oversized);
  EXPECT_EQ(parse(r, reply(0x1234, 7, {0x83, 0})), ClientError::Malformed);
}

TEST(ModbusClientFrame, WritesMustBeEchoed) {
  ClientRequest w;
  w.function = ModbusFunction::WriteSingleRegister;
  w.transaction = 9;
  w.unit = 1;
  w.address = 100;
  std::uint16_t v = 0xBEEF;
  w.registers = &v;
  EXPECT_EQ(parse(w, reply(9, 1, {6, 0, 100, 0xBE, 0xEF})), ClientError::None);
  EXPECT_EQ(parse(w, reply(9, 1, {6, 0, 100, 0xBE, 0xEE})), ClientError::WrongEcho);
  EXPECT_EQ(parse(w, reply(9, 1, {6, 0, 101, 0xBE, 0xEF})), ClientError::WrongEcho);
  EXPECT_EQ(parse(w, reply(9, 1, {6, 0, 100, 0xBE})), ClientError::Short);
  EXPECT_EQ(parse(w, reply(9, 1, {6, 0, 100, 0xBE, 0xEF, 0})), ClientError::Oversized);

  ClientRequest m;
  m.function = ModbusFunction::WriteMultipleCoils;
  m.transaction = 10;
  m.unit = 1;
  m.address = 3;
  m.quantity = 12;
  EXPECT_EQ(parse(m, reply(10, 1, {15, 0, 3, 0, 12})), ClientError::None);
  EXPECT_EQ(parse(m, reply(10, 1, {15, 0, 3, 0, 11})), ClientError::WrongEcho);
}

TEST(ModbusClientFrame, ReadsOfCoilsCountBytesOfEightCoils) {
  ClientRequest r;
  r.function = ModbusFunction::ReadCoils;
  r.transaction = 1;
  r.unit = 1;
  r.quantity = 10;
  EXPECT_EQ(parse(r, reply(1, 1, {1, 2, 0xCD, 0x01})), ClientError::None);
  EXPECT_EQ(parse(r, reply(1, 1, {1, 1, 0xCD})), ClientError::WrongByteCount);
  std::vector<Cell> v(10);
  const std::uint8_t data[2] = {0xCD, 0x01};
  values_from_bits(data, 10, v.data());
  const int want[10] = {1, 0, 1, 1, 0, 0, 1, 1, 1, 0};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(v[static_cast<std::size_t>(i)].get<bool>(), want[i] == 1) << i;
}

// Registers as the reply carries them (big-endian bytes).
Bytes wire(const std::vector<std::uint16_t>& regs) {
  Bytes b;
  for (auto r : regs) {
    b.push_back(static_cast<std::uint8_t>(r >> 8));
    b.push_back(static_cast<std::uint8_t>(r));
  }
  return b;
}

TEST(ModbusClientValues, TypesAndWordOrdersAsTheServerEncodesThem) {
  ValueFormat f;
  f.wire = IecType::DINT;
  f.order = WordOrder::HighFirst;
  Cell c;
  values_from_registers(f, wire({0x0001, 0x0002}).data(), 1, &c);
  EXPECT_EQ(c.get<std::int32_t>(), 0x00010002);
  f.order = WordOrder::LowFirst;
  values_from_registers(f, wire({0x0001, 0x0002}).data(), 1, &c);
  EXPECT_EQ(c.get<std::int32_t>(), 0x00020001);

  for (auto order : {WordOrder::HighFirst, WordOrder::LowFirst})
    for (IecType t : {IecType::INT, IecType::UINT, IecType::DINT, IecType::UDINT, IecType::LINT, IecType::REAL,
                      IecType::LREAL, IecType::WORD, IecType::DWORD, IecType::SINT}) {
      ValueFormat g;
      g.wire = t;
      g.order = order;
      Cell in[2];
      if (t == IecType::REAL) { in[0].set<float>(-1.5f); in[1].set<float>(3e7f); }
      else if (t == IecType::LREAL) { in[0].set<double>(-2.25); in[1].set<double>(1e300); }
      else if (t == IecType::SINT) { in[0].set<std::int8_t>(-3); in[1].set<std::int8_t>(100); }
      else { in[0].raw = 0x1234; in[1].raw = t == IecType::INT || t == IecType::UINT || t == IecType::WORD ? 0xFEDC : 0x89ABCDEF; }
      std::vector<std::uint16_t> regs(2 * g.width());
      values_to_registers(g, in, 2, regs.data());
      Cell out[2];
      values_from_registers(g, wire(regs).data(), 2, out);
      EXPECT_EQ(out[0].raw, in[0].raw) << type_name(t);
      EXPECT_EQ(out[1].raw, in[1].raw) << type_name(t);
    }
}

TEST(ModbusClientValues, ScaledValuesRoundAndClamp) {
  ValueFormat f;
  f.wire = IecType::INT;
  f.scaled = true;
  f.scale = 0.1;
  f.offset = -50;
  Cell c;
  values_from_registers(f, wire({250}).data(), 1, &c);
  EXPECT_DOUBLE_EQ(c.get<double>(), -25.0);
  Cell in[4];
  in[0].set<double>(-25.0);
  in[1].set<double>(1e9);      // clamps to 32767
  in[2].set<double>(-1e9);     // clamps to -32768
  in[3].set<double>(std::nan(""));  // writes 0
  std::uint16_t regs[4];
  values_to_registers(f, in, 4, regs);
  EXPECT_EQ(regs[0], 250);
  EXPECT_EQ(regs[1], 32767);
  EXPECT_EQ(regs[2], 0x8000);
  EXPECT_EQ(regs[3], 0);
  f.wire = IecType::ULINT;
  f.scale = 1;
  f.offset = 0;
  in[0].set<double>(1e30);
  std::uint16_t big[4];
  values_to_registers(f, in, 1, big);
  EXPECT_EQ(big[0], 0xFFFF);
  EXPECT_EQ(big[3], 0xFFFF);
}

}  // namespace
}  // namespace syncplc
