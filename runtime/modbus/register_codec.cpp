#include "runtime/modbus/register_codec.hpp"

#include <cstring>
#include <type_traits>

namespace syncplc {

std::uint32_t register_width(IecType t) {
  if (t == IecType::BOOL) return 1;
  const int bits = bit_width(t);
  return bits <= 16 ? 1u : static_cast<std::uint32_t>(bits / 16);
}

namespace {

// The value's bits as an unsigned integer of its width (reals by their IEEE
// pattern, signed integers two's complement).
std::uint64_t raw_bits(IecType t, Cell c) {
  return dispatch_type(t, [&]<IecType T>() -> std::uint64_t {
    using N = typename Native<T>::type;
    N v = c.get<N>();
    if constexpr (std::is_same_v<N, bool>) return v ? 1u : 0u;
    else if constexpr (std::is_same_v<N, float>) { std::uint32_t u; std::memcpy(&u, &v, 4); return u; }
    else if constexpr (std::is_same_v<N, double>) { std::uint64_t u; std::memcpy(&u, &v, 8); return u; }
    else return static_cast<std::uint64_t>(static_cast<std::make_unsigned_t<N>>(v));
  });
}

Cell from_bits(IecType t, std::uint64_t u) {
  Cell c;
  dispatch_type(t, [&]<IecType T>() {
    using N = typename Native<T>::type;
    if constexpr (std::is_same_v<N, bool>) c.set<bool>(u != 0);
    else if constexpr (std::is_same_v<N, float>) { float f; auto w = static_cast<std::uint32_t>(u); std::memcpy(&f, &w, 4); c.set<float>(f); }
    else if constexpr (std::is_same_v<N, double>) { double d; std::memcpy(&d, &u, 8); c.set<double>(d); }
    else c.set<N>(static_cast<N>(static_cast<std::make_unsigned_t<N>>(u)));
  });
  return c;
}

}  // namespace

void encode_registers(IecType t, Cell c, WordOrder order, std::uint16_t* regs) {
  const std::uint32_t n = register_width(t);
  if (n == 1 && t != IecType::SINT) {
    // One register: the value's bits are the low bits of the cell (Cell::set zeroes the rest).
    regs[0] = static_cast<std::uint16_t>(c.raw);
    return;
  }
  if (t == IecType::SINT) {
    // Sign-extended, as an HMI reading a signed register expects (-1 is FFFF, not 00FF).
    regs[0] = static_cast<std::uint16_t>(static_cast<std::int16_t>(c.get<std::int8_t>()));
    return;
  }
  const std::uint64_t u = raw_bits(t, c);
  for (std::uint32_t i = 0; i < n; ++i) {
    // i = 0 is the most significant word in HighFirst order.
    const std::uint32_t word = order == WordOrder::HighFirst ? n - 1 - i : i;
    regs[i] = static_cast<std::uint16_t>(u >> (16 * word));
  }
}

Cell decode_registers(IecType t, const std::uint16_t* regs, WordOrder order) {
  const std::uint32_t n = register_width(t);
  std::uint64_t u = 0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t word = order == WordOrder::HighFirst ? n - 1 - i : i;
    u |= std::uint64_t{regs[i]} << (16 * word);
  }
  if (bit_width(t) == 8) u &= 0xFF;
  return from_bits(t, u);
}

}  // namespace syncplc
