#include "runtime/io/modbus_client/client_frame.hpp"

namespace syncplc {
namespace {

void put16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
std::uint16_t get16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] << 8 | p[1]); }

std::size_t put_registers(std::uint8_t* p, const std::uint16_t* regs, std::uint16_t n) {
  for (std::uint16_t i = 0; i < n; ++i) put16(p + 2 * i, regs ? regs[i] : 0);
  return 2u * n;
}

}  // namespace

bool is_bit_function(ModbusFunction f) {
  return f == ModbusFunction::ReadCoils || f == ModbusFunction::ReadDiscreteInputs ||
         f == ModbusFunction::WriteSingleCoil || f == ModbusFunction::WriteMultipleCoils;
}
bool function_reads(ModbusFunction f) {
  return static_cast<int>(f) <= 4 || f == ModbusFunction::ReadWriteMultipleRegisters;
}
bool function_writes(ModbusFunction f) { return !function_reads(f) || f == ModbusFunction::ReadWriteMultipleRegisters; }

std::uint32_t max_quantity(ModbusFunction f) {
  switch (f) {
    case ModbusFunction::ReadCoils:
    case ModbusFunction::ReadDiscreteInputs: return 2000;   // §6.1, §6.2
    case ModbusFunction::ReadHoldingRegisters:
    case ModbusFunction::ReadInputRegisters:
    case ModbusFunction::ReadWriteMultipleRegisters: return 125;  // §6.3, §6.4, §6.17
    case ModbusFunction::WriteSingleCoil:
    case ModbusFunction::WriteSingleRegister: return 1;
    case ModbusFunction::WriteMultipleCoils: return 1968;  // §6.11
    case ModbusFunction::WriteMultipleRegisters: return 123;  // §6.12
  }
  return 0;
}
std::uint32_t max_write_quantity(ModbusFunction f) {
  return f == ModbusFunction::ReadWriteMultipleRegisters ? 121 : max_quantity(f);  // §6.17
}

std::size_t build_request(const ClientRequest& r, std::uint8_t* out) {
  std::uint8_t* pdu = out + kMbapBytes;
  pdu[0] = static_cast<std::uint8_t>(r.function);
  std::size_t n = 1;
  switch (r.function) {
    case ModbusFunction::ReadCoils:
    case ModbusFunction::ReadDiscreteInputs:
    case ModbusFunction::ReadHoldingRegisters:
    case ModbusFunction::ReadInputRegisters:
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.quantity);
      n = 5;
      break;
    case ModbusFunction::WriteSingleCoil:
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.bits && r.bits[0] ? 0xFF00 : 0x0000);  // §6.5: FF00 on, 0000 off
      n = 5;
      break;
    case ModbusFunction::WriteSingleRegister:
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.registers ? r.registers[0] : 0);
      n = 5;
      break;
    case ModbusFunction::WriteMultipleCoils: {
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.quantity);
      const std::size_t bytes = (r.quantity + 7u) / 8u;
      pdu[5] = static_cast<std::uint8_t>(bytes);
      for (std::size_t i = 0; i < bytes; ++i) pdu[6 + i] = 0;
      for (std::uint16_t i = 0; i < r.quantity; ++i)
        if (r.bits && r.bits[i]) pdu[6 + i / 8] = static_cast<std::uint8_t>(pdu[6 + i / 8] | (1u << (i % 8)));
      n = 6 + bytes;
      break;
    }
    case ModbusFunction::WriteMultipleRegisters:
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.quantity);
      pdu[5] = static_cast<std::uint8_t>(2 * r.quantity);
      n = 6 + put_registers(pdu + 6, r.registers, r.quantity);
      break;
    case ModbusFunction::ReadWriteMultipleRegisters:
      put16(pdu + 1, r.address);
      put16(pdu + 3, r.quantity);
      put16(pdu + 5, r.write_address);
      put16(pdu + 7, r.write_quantity);
      pdu[9] = static_cast<std::uint8_t>(2 * r.write_quantity);
      n = 10 + put_registers(pdu + 10, r.registers, r.write_quantity);
      break;
  }
  put16(out, r.transaction);
  put16(out + 2, 0);  // protocol id: Modbus
  put16(out + 4, static_cast<std::uint16_t>(n + 1));
  out[6] = r.unit;
  return kMbapBytes + n;
}

ClientReply parse_reply(const ClientRequest& r, const std::uint8_t* adu, std::size_t n) {
  ClientReply out;
  auto fail = [&out](ClientError e) {
    out.error = e;
    return out;
  };
  if (n < kMbapBytes + 1) return fail(ClientError::Short);
  if (get16(adu + 2) != 0) return fail(ClientError::Malformed);
  const std::size_t length = mbap_length(adu);
  if (length > kMaxAdu - 6) return fail(ClientError::Oversized);
  if (length < 2 || 6 + length != n) return fail(ClientError::Malformed);
  if (get16(adu) != r.transaction) return fail(ClientError::WrongTransaction);
  if (adu[6] != r.unit) return fail(ClientError::WrongUnit);
  const std::uint8_t* pdu = adu + kMbapBytes;
  const std::size_t pdu_n = n - kMbapBytes;
  const auto fc = static_cast<std::uint8_t>(r.function);
  if (pdu[0] == (fc | 0x80)) {  // exception reply: function | 0x80, one exception code (§7)
    if (pdu_n < 2) return fail(ClientError::Short);
    if (pdu_n > 2) return fail(ClientError::Oversized);
    if (pdu[1] == 0) return fail(ClientError::Malformed);  // 0 is no exception code
    return fail(exception_error(pdu[1]));
  }
  if (pdu[0] != fc) return fail(ClientError::WrongFunction);
  switch (r.function) {
    case ModbusFunction::ReadCoils:
    case ModbusFunction::ReadDiscreteInputs:
    case ModbusFunction::ReadHoldingRegisters:
    case ModbusFunction::ReadInputRegisters:
    case ModbusFunction::ReadWriteMultipleRegisters: {
      if (pdu_n < 2) return fail(ClientError::Short);
      const std::size_t bytes = pdu[1];
      if (pdu_n - 2 < bytes) return fail(ClientError::Short);
      if (pdu_n - 2 > bytes) return fail(ClientError::Oversized);
      const std::size_t want = is_bit_function(r.function) ? (r.quantity + 7u) / 8u : 2u * r.quantity;
      if (bytes != want) return fail(ClientError::WrongByteCount);
      out.data = pdu + 2;
      out.bytes = bytes;
      return out;
    }
    case ModbusFunction::WriteSingleCoil:
    case ModbusFunction::WriteSingleRegister:
    case ModbusFunction::WriteMultipleCoils:
    case ModbusFunction::WriteMultipleRegisters: {
      // §6.5, §6.6: the request echoed; §6.11, §6.12: address and quantity.
      if (pdu_n < 5) return fail(ClientError::Short);
      if (pdu_n > 5) return fail(ClientError::Oversized);
      std::uint16_t second = r.quantity;
      if (r.function == ModbusFunction::WriteSingleCoil) second = r.bits && r.bits[0] ? 0xFF00 : 0x0000;
      if (r.function == ModbusFunction::WriteSingleRegister) second = r.registers ? r.registers[0] : 0;
      if (get16(pdu + 1) != r.address || get16(pdu + 3) != second) return fail(ClientError::WrongEcho);
      return out;
    }
  }
  return fail(ClientError::WrongFunction);
}

}  // namespace syncplc
