// Building Modbus TCP requests byte by byte for the handler and fuzzer tests.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <vector>

namespace syncplc::testing {

using Bytes = std::vector<std::uint8_t>;

inline void put16(Bytes& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v >> 8));
  b.push_back(static_cast<std::uint8_t>(v & 0xFF));
}

// MBAP header (transaction id, protocol 0, length, unit) + PDU.
inline Bytes frame(const Bytes& pdu, std::uint8_t unit = 1, std::uint16_t tid = 0x1234) {
  Bytes b;
  put16(b, tid);
  put16(b, 0);
  put16(b, static_cast<std::uint16_t>(pdu.size() + 1));
  b.push_back(unit);
  b.insert(b.end(), pdu.begin(), pdu.end());
  return b;
}

// fc address quantity (FC 1..4), or fc address value (FC 5, 6).
inline Bytes pdu(std::uint8_t fc, std::uint16_t a, std::uint16_t q) {
  Bytes b{fc};
  put16(b, a);
  put16(b, q);
  return b;
}

// FC 16 with the given register values.
inline Bytes write_registers(std::uint16_t a, std::initializer_list<std::uint16_t> regs) {
  Bytes b = pdu(0x10, a, static_cast<std::uint16_t>(regs.size()));
  b.push_back(static_cast<std::uint8_t>(2 * regs.size()));
  for (auto r : regs) put16(b, r);
  return b;
}

// FC 15 with the given coil states.
inline Bytes write_coils(std::uint16_t a, std::initializer_list<bool> bits) {
  Bytes b = pdu(0x0F, a, static_cast<std::uint16_t>(bits.size()));
  Bytes packed((bits.size() + 7) / 8, 0);
  std::size_t i = 0;
  for (bool v : bits) {
    if (v) packed[i / 8] |= static_cast<std::uint8_t>(1u << (i % 8));
    ++i;
  }
  b.push_back(static_cast<std::uint8_t>(packed.size()));
  b.insert(b.end(), packed.begin(), packed.end());
  return b;
}

// FC 23: read [ra, ra+rq) after writing regs at wa.
inline Bytes write_read(std::uint16_t ra, std::uint16_t rq, std::uint16_t wa, std::initializer_list<std::uint16_t> regs) {
  Bytes b = pdu(0x17, ra, rq);
  put16(b, wa);
  put16(b, static_cast<std::uint16_t>(regs.size()));
  b.push_back(static_cast<std::uint8_t>(2 * regs.size()));
  for (auto r : regs) put16(b, r);
  return b;
}

}  // namespace syncplc::testing
