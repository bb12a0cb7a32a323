// The Modbus TCP client's frames (Modbus Messaging on TCP/IP Implementation
// Guide v1.0b §3.1.3, Modbus Application Protocol v1.1b3 §6): one request
// ADU built from a request group, and the checks of one reply ADU against
// the request it answers. The reply is untrusted input: parse_reply reads
// only within [adu, adu + n), whatever the bytes say, and classifies every
// deviation (client_error.hpp). Hand-written rather than libmodbus's client
// calls: libmodbus folds these classes into one errno (EMBBADDATA), frames a
// reply by its function code instead of the MBAP length (an oversized reply
// leaves bytes in the stream), and cannot be driven without a socket, so it
// could not be fuzzed as a pure function (fuzz/modbus_reply_fuzzer.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "runtime/io/modbus_client/client_error.hpp"

namespace syncplc {

// MBAP header (7 bytes) + function code + at most 252 bytes of data.
inline constexpr std::size_t kMbapBytes = 7;
inline constexpr std::size_t kMaxAdu = 260;

enum class ModbusFunction : std::uint8_t {
  ReadCoils = 1,
  ReadDiscreteInputs = 2,
  ReadHoldingRegisters = 3,
  ReadInputRegisters = 4,
  WriteSingleCoil = 5,
  WriteSingleRegister = 6,
  WriteMultipleCoils = 15,
  WriteMultipleRegisters = 16,
  ReadWriteMultipleRegisters = 23,
};

bool is_bit_function(ModbusFunction f);     // 1, 2, 5, 15: coils or discrete inputs
bool function_reads(ModbusFunction f);      // 1, 2, 3, 4, 23
bool function_writes(ModbusFunction f);     // 5, 6, 15, 16, 23
// Largest quantity one request may carry (App. Protocol §6): the read side;
// for 23 max_write_quantity is the write side.
std::uint32_t max_quantity(ModbusFunction f);
std::uint32_t max_write_quantity(ModbusFunction f);

// One request: quantities in coils or registers.
struct ClientRequest {
  ModbusFunction function = ModbusFunction::ReadHoldingRegisters;
  std::uint8_t unit = 1;
  std::uint16_t transaction = 0;
  std::uint16_t address = 0;        // the read address (23: the read side); the write address otherwise
  std::uint16_t quantity = 1;       // read quantity; write quantity for 5, 6, 15, 16
  std::uint16_t write_address = 0;  // 23 only
  std::uint16_t write_quantity = 0; // 23 only
  const std::uint16_t* registers = nullptr;  // values to write (6, 16, 23)
  const std::uint8_t* bits = nullptr;        // coils to write, one byte (0/1) each (5, 15)
};

// Writes the request ADU to out (kMaxAdu bytes); returns its length.
std::size_t build_request(const ClientRequest& r, std::uint8_t* out);

struct ClientReply {
  ClientError error = ClientError::None;  // exception_error(code) for an exception reply
  const std::uint8_t* data = nullptr;     // read replies: the data bytes (after the byte count)
  std::size_t bytes = 0;
};

// The checks, in order: a whole MBAP header and function code (Short),
// protocol id 0 and a length field that matches n (Malformed; above 254:
// Oversized), transaction id, unit id, exception reply (one code byte),
// function code, then the function's own layout: byte count against the
// data present (Short/Oversized) and against the request's quantity
// (WrongByteCount), a write's echo (WrongEcho).
ClientReply parse_reply(const ClientRequest& r, const std::uint8_t* adu, std::size_t n);

// The MBAP length field of a header: the bytes after the first six. The
// receiver reads that many more; above 254 the frame cannot be Modbus.
inline std::size_t mbap_length(const std::uint8_t* header) {
  return static_cast<std::size_t>(header[4]) << 8 | header[5];
}

}  // namespace syncplc
