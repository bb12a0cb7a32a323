// The register encoding of IEC values, shared by the Modbus server
// (register_map.*) and the Modbus client driver (runtime/io/modbus_client):
// 16-bit values in one register, 32- and 64-bit values in two or four, high
// word first (WordOrder::HighFirst) or swapped (LowFirst); each register is
// big-endian on the wire, as Modbus defines. SINT is sign-extended into its
// register; USINT and BYTE take the low byte when decoded.
#pragma once

#include <cstdint>

#include "runtime/core/iec_type.hpp"
#include "runtime/modbus/modbus_config.hpp"

namespace syncplc {

// Registers a value of type t takes (bits for BOOL count as one coil).
std::uint32_t register_width(IecType t);
// A cell as registers (width register_width(t)) and back.
void encode_registers(IecType t, Cell c, WordOrder order, std::uint16_t* regs);
Cell decode_registers(IecType t, const std::uint16_t* regs, WordOrder order);

}  // namespace syncplc
