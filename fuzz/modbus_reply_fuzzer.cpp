// libFuzzer harness on the Modbus client's reply path: one request of the
// modbus_client driver (runtime/io/modbus_client/client_frame.hpp) and the
// bytes a device answers with, through parse_reply and, when it accepts
// them, the decoding of the values (wire_values.hpp) as the device thread
// does it. Besides ASan/UBSan, it checks that an accepted reply's data lie
// inside the buffer and are exactly what the request's quantity needs, that
// an exception reply is exactly 9 bytes, and that a rejected one names a
// class (client_error.hpp).
//
// Input: byte 0 picks the function (of the nine), byte 1 the quantity
// (1 + byte % the function's limit), byte 2 the type of register values,
// byte 3 the word order and unit; the rest is the reply ADU as received
// (transaction id 0x0102 expected).
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "runtime/io/modbus_client/client_frame.hpp"
#include "runtime/io/modbus_client/wire_values.hpp"

namespace {

using namespace syncplc;

constexpr ModbusFunction kFunctions[] = {
    ModbusFunction::ReadCoils,          ModbusFunction::ReadDiscreteInputs,     ModbusFunction::ReadHoldingRegisters,
    ModbusFunction::ReadInputRegisters, ModbusFunction::WriteSingleCoil,        ModbusFunction::WriteSingleRegister,
    ModbusFunction::WriteMultipleCoils, ModbusFunction::WriteMultipleRegisters, ModbusFunction::ReadWriteMultipleRegisters,
};
constexpr IecType kTypes[] = {IecType::INT,   IecType::UINT, IecType::DINT, IecType::UDINT, IecType::LINT,
                              IecType::ULINT, IecType::REAL, IecType::LREAL, IecType::WORD, IecType::SINT};

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  ClientRequest r;
  r.function = kFunctions[data[0] % 9];
  ValueFormat f;
  f.wire = is_bit_function(r.function) ? IecType::BOOL : kTypes[data[2] % 10];
  f.order = (data[3] & 1) ? WordOrder::LowFirst : WordOrder::HighFirst;
  f.scaled = (data[3] & 2) != 0 && f.wire != IecType::BOOL;
  f.scale = 0.5;
  const std::uint32_t width = f.width();
  const std::uint32_t limit = max_quantity(r.function) / width;
  if (limit == 0) return 0;  // a 64-bit value in one register (function 6)
  const std::uint32_t values = 1 + data[1] % limit;
  r.quantity = static_cast<std::uint16_t>(values * width);
  r.unit = static_cast<std::uint8_t>(data[3] >> 2);
  r.transaction = 0x0102;
  r.address = 100;
  std::vector<std::uint16_t> regs(r.quantity, 0x1234);
  std::vector<std::uint8_t> bits(r.quantity, 1);
  r.registers = regs.data();
  r.bits = bits.data();
  if (r.function == ModbusFunction::ReadWriteMultipleRegisters) {
    r.write_address = 7;
    r.write_quantity = static_cast<std::uint16_t>(std::min<std::uint32_t>(r.quantity, 121 / width * width));
  }
  // The request is built as the device thread builds it (bounded buffer).
  std::uint8_t req[kMaxAdu];
  check(build_request(r, req) <= kMaxAdu);

  // The reply in a buffer of its own size, so ASan sees any read past it.
  std::vector<std::uint8_t> adu(data + 4, data + size);
  const ClientReply reply = parse_reply(r, adu.data(), adu.size());
  const auto e = code(reply.error);
  if (e == 0) {
    check(adu.size() >= kMbapBytes + 1 && adu.size() <= kMaxAdu);
    if (function_reads(r.function)) {
      check(reply.data >= adu.data() && reply.data + reply.bytes == adu.data() + adu.size());
      check(reply.bytes == (is_bit_function(r.function) ? (r.quantity + 7u) / 8u : 2u * r.quantity));
      std::vector<Cell> out(values);
      if (f.wire == IecType::BOOL) values_from_bits(reply.data, values, out.data());
      else values_from_registers(f, reply.data, values, out.data());
    } else {
      check(adu.size() == 12);
    }
  } else if (e <= 255) {
    check(adu.size() == 9 && adu[7] == (static_cast<std::uint8_t>(r.function) | 0x80) && adu[8] == e);
  } else {
    check(e >= 256 && e <= 268);
  }
  return 0;
}
