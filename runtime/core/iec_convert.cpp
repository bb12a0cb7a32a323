#include "runtime/core/iec_convert.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace syncplc {
namespace {

template <IecType T>
using native_t = typename Native<T>::type;

constexpr bool is_bits(IecType t) {
  return t == IecType::BYTE || t == IecType::WORD || t == IecType::DWORD || t == IecType::LWORD;
}

// 128-bit integers hold every 64-bit value, signed or not, and their
// products by 10^6 (a GCC/Clang extension; the build uses -Wpedantic).
__extension__ using i128 = __int128;
__extension__ using u128 = unsigned __int128;

constexpr double kNsPerMs = 1e6;

// A source value: an exact integer or a real.
struct Value {
  bool real = false;
  i128 i = 0;
  double r = 0;
};

template <IecType S>
Value read_source(Cell c) noexcept {
  using V = native_t<S>;
  const V v = c.get<V>();
  Value x;
  if constexpr (S == IecType::REAL || S == IecType::LREAL) {
    x.real = true;
    x.r = static_cast<double>(v);
  } else if constexpr (S == IecType::TIME) {
    if (v % 1'000'000 == 0) x.i = v / 1'000'000;
    else x.real = true, x.r = static_cast<double>(v) / kNsPerMs;
  } else {
    x.i = static_cast<i128>(v);  // BOOL 0/1, integers, bit strings (unsigned)
  }
  return x;
}

enum class Rounding { Nearest, Trunc };

// The integer a real becomes: nearest (ties to even) or toward zero.
inline double to_integral(double r, Rounding m) noexcept {
  return m == Rounding::Trunc ? std::trunc(r) : std::nearbyint(r);  // default mode: to nearest, ties to even
}

// Clamps v to [lo, hi]; *out_of_range when it had to.
inline i128 clamp128(i128 v, i128 lo, i128 hi, bool* out_of_range) noexcept {
  if (v < lo) { *out_of_range = true; return lo; }
  if (v > hi) { *out_of_range = true; return hi; }
  return v;
}

// A real as an integer in [lo, hi] (saturated; NaN gives 0, out of range).
inline i128 real_to_int(double r, Rounding m, i128 lo, i128 hi, bool* out_of_range) noexcept {
  if (std::isnan(r)) { *out_of_range = true; return 0; }
  const double q = to_integral(r, m);
  if (q < static_cast<double>(lo)) { *out_of_range = true; return lo; }
  if (q > static_cast<double>(hi)) { *out_of_range = true; return hi; }
  // |q| <= 2^64 here, exact in i128; double(hi) may round up (2^64 - 1 -> 2^64).
  return clamp128(static_cast<i128>(q), lo, hi, out_of_range);
}

template <IecType S, IecType D, Rounding M>
Cell convert(Cell in, bool* out_of_range) noexcept {
  using DV = native_t<D>;
  if constexpr (S == D) return in;  // the cell as it is, without reading it as a value
  const Value x = read_source<S>(in);
  Cell out;
  if constexpr (D == IecType::BOOL) {
    out.set<bool>(x.real ? x.r != 0 : x.i != 0);
  } else if constexpr (D == IecType::REAL || D == IecType::LREAL) {
    double r = x.real ? x.r : static_cast<double>(x.i);
    if constexpr (D == IecType::REAL) {
      constexpr double kMax = std::numeric_limits<float>::max();
      if (r > kMax || r < -kMax) {
        *out_of_range = true;
        r = r > 0 ? kMax : -kMax;
      }
    }
    out.set<DV>(static_cast<DV>(r));
  } else if constexpr (D == IecType::TIME) {
    constexpr auto lo = static_cast<i128>(std::numeric_limits<std::int64_t>::min());
    constexpr auto hi = static_cast<i128>(std::numeric_limits<std::int64_t>::max());
    i128 ns;
    if (x.real) {
      const double q = M == Rounding::Trunc ? std::trunc(x.r * kNsPerMs) : std::nearbyint(x.r * kNsPerMs);
      const bool bad = !(q >= -9.2e18 && q <= 9.2e18);  // NaN too
      ns = std::isnan(q) ? 0 : q < -9.2e18 ? lo : q > 9.2e18 ? hi : static_cast<i128>(q);
      if (bad) *out_of_range = true;
    } else {
      ns = clamp128(x.i * 1'000'000, lo, hi, out_of_range);
    }
    out.set<std::int64_t>(static_cast<std::int64_t>(ns));
  } else if constexpr (is_bits(D)) {
    // The low bits of the two's-complement pattern.
    constexpr i128 umax = static_cast<i128>(std::numeric_limits<DV>::max());
    const i128 v = x.real ? real_to_int(x.r, M, 0, umax, out_of_range) : x.i;
    out.set<DV>(static_cast<DV>(static_cast<u128>(v)));
  } else {  // a signed or unsigned integer
    constexpr auto lo = static_cast<i128>(std::numeric_limits<DV>::min());
    constexpr auto hi = static_cast<i128>(std::numeric_limits<DV>::max());
    if constexpr (is_bits(S) && sizeof(native_t<S>) == sizeof(DV)) {
      out.set<DV>(static_cast<DV>(in.get<native_t<S>>()));  // same width: the bits, reinterpreted
    } else if (x.real) {
      out.set<DV>(static_cast<DV>(real_to_int(x.r, M, lo, hi, out_of_range)));
    } else {
      out.set<DV>(static_cast<DV>(clamp128(x.i, lo, hi, out_of_range)));
    }
  }
  return out;
}

// The table: index (from * 16 + to) * 2 + trunc.
template <std::size_t I>
constexpr ConvertFn entry() {
  constexpr auto s = static_cast<IecType>(I / 2 / kIecTypeCount);
  constexpr auto d = static_cast<IecType>(I / 2 % kIecTypeCount);
  return &convert<s, d, I % 2 ? Rounding::Trunc : Rounding::Nearest>;
}

template <std::size_t... I>
constexpr std::array<ConvertFn, sizeof...(I)> make_table(std::index_sequence<I...>) {
  return {entry<I>()...};
}

constexpr auto kTable = make_table(std::make_index_sequence<kIecTypeCount * kIecTypeCount * 2>());

}  // namespace

ConvertFn conversion_fn(IecType from, IecType to, bool trunc) noexcept {
  const auto f = static_cast<std::size_t>(from), t = static_cast<std::size_t>(to);
  if (f >= kIecTypeCount || t >= kIecTypeCount) return kTable[0];  // not an IecType: BOOL's identity
  return kTable[(f * kIecTypeCount + t) * 2 + (trunc ? 1 : 0)];
}

}  // namespace syncplc
