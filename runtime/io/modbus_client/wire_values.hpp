// A request group's values on the wire: registers through the server's
// register codec (runtime/modbus/register_codec.hpp, the same word orders),
// coils packed eight to a byte, least significant bit first (App. Protocol
// §6.1). Scaled groups: channel value = raw * scale + offset; written values
// are converted back, rounded to the nearest integer and clamped to the
// register type's range (a NaN writes 0). No allocation: these run on the
// device threads with buffers sized at load.
#pragma once

#include <cstdint>

#include "runtime/io/modbus_client/client_config.hpp"

namespace syncplc {

// data: 2 * count * width big-endian bytes (a read reply's data).
void values_from_registers(const ValueFormat& f, const std::uint8_t* data, std::uint32_t count, Cell* out) noexcept;
// data: (count + 7) / 8 bytes.
void values_from_bits(const std::uint8_t* data, std::uint32_t count, Cell* out) noexcept;
// regs: count * width registers.
void values_to_registers(const ValueFormat& f, const Cell* in, std::uint32_t count, std::uint16_t* regs) noexcept;
// bits: count bytes, 0 or 1.
void values_to_bits(const Cell* in, std::uint32_t count, std::uint8_t* bits) noexcept;

}  // namespace syncplc
