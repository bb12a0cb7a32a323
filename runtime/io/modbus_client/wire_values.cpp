#include "runtime/io/modbus_client/wire_values.hpp"

#include <cmath>
#include <limits>
#include <type_traits>

#include "runtime/modbus/register_codec.hpp"

namespace syncplc {
namespace {

// The raw register value of a channel value v (scaled groups).
Cell raw_of(IecType wire, double v) {
  Cell c;
  dispatch_type(wire, [&]<IecType T>() {
    using N = typename Native<T>::type;
    if constexpr (std::is_floating_point_v<N>) {
      c.set<N>(static_cast<N>(v));
    } else if constexpr (std::is_same_v<N, bool>) {
      c.set<bool>(v != 0);
    } else {
      // Clamp in double, then convert: out-of-range conversion would be undefined.
      const double lo = static_cast<double>(std::numeric_limits<N>::min());
      const double hi = static_cast<double>(std::numeric_limits<N>::max());
      double r = std::isnan(v) ? 0.0 : std::nearbyint(v);
      N n;
      if (r <= lo) n = std::numeric_limits<N>::min();
      else if (r >= hi) n = std::numeric_limits<N>::max();  // hi rounds up for 64-bit types: >= keeps it in range
      else n = static_cast<N>(r);
      c.set<N>(n);
    }
  });
  return c;
}

}  // namespace

void values_from_registers(const ValueFormat& f, const std::uint8_t* data, std::uint32_t count, Cell* out) noexcept {
  const std::uint32_t w = f.width();
  std::uint16_t regs[4];
  for (std::uint32_t i = 0; i < count; ++i) {
    for (std::uint32_t k = 0; k < w; ++k) {
      const std::uint8_t* p = data + 2 * (i * w + k);
      regs[k] = static_cast<std::uint16_t>(p[0] << 8 | p[1]);
    }
    const Cell raw = decode_registers(f.wire, regs, f.order);
    if (f.scaled) out[i].set<double>(cell_as_double(f.wire, raw) * f.scale + f.offset);
    else out[i] = raw;
  }
}

void values_from_bits(const std::uint8_t* data, std::uint32_t count, Cell* out) noexcept {
  for (std::uint32_t i = 0; i < count; ++i) out[i].set<bool>((data[i / 8] >> (i % 8)) & 1);
}

void values_to_registers(const ValueFormat& f, const Cell* in, std::uint32_t count, std::uint16_t* regs) noexcept {
  const std::uint32_t w = f.width();
  for (std::uint32_t i = 0; i < count; ++i) {
    const Cell raw = f.scaled ? raw_of(f.wire, (in[i].get<double>() - f.offset) / f.scale) : in[i];
    encode_registers(f.wire, raw, f.order, regs + i * w);
  }
}

void values_to_bits(const Cell* in, std::uint32_t count, std::uint8_t* bits) noexcept {
  for (std::uint32_t i = 0; i < count; ++i) bits[i] = in[i].get<bool>() ? 1 : 0;
}

}  // namespace syncplc
