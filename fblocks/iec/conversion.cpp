// IEC 61131-3 type conversion functions *_TO_** between every pair of
// elementary types, and the truncations REAL_TRUNC_** / LREAL_TRUNC_**,
// generated from the type list (IEC 61131-3 ed. 2, 2.5.1.5.1, Table 22; the
// typed *_TRUNC_** names are those of ed. 3).
//
// The rules (the standard leaves out-of-range results implementation-defined;
// syncplc saturates and raises a fault, so a wrapped value never reaches an
// actuator unnoticed):
//   - REAL/LREAL to an integer: round to nearest, ties to even (IEC 60559, as
//     Table 22 note b prescribes: 2.5 -> 2, -1.5 -> -2); *_TRUNC_* rounds
//     toward zero (note c).
//   - to an integer (SINT..ULINT) or REAL: a value outside the target's range
//     gives the nearest representable value (the minimum or maximum) and a
//     block-fault event "conversion out of range" with the value.
//   - to a bit string (BYTE..LWORD): the low bits of the value's two's-
//     complement pattern (INT_TO_WORD(-1) = 16#FFFF, DWORD_TO_BYTE(16#1234)
//     = 16#34), no fault; from a real, the rounded value must fit
//     0 .. 2^N - 1 (else saturated, fault).
//   - a bit string to a signed integer of the same width is a reinterpretation
//     of the bits (WORD_TO_INT(16#FFFF) = -1), no fault; otherwise bit strings
//     count as unsigned numbers.
//   - BOOL: FALSE -> 0, TRUE -> 1; to BOOL: TRUE when the value is not 0.
//   - TIME: counted in milliseconds against numbers and bit strings (as
//     CODESYS TIME_TO_DINT); TIME_TO_LREAL(T#1.5ms) = 1.5; to an integer a
//     fraction of a millisecond rounds like a real. BOOL_TO_TIME(TRUE) = T#1ms.
#include <cfenv>
#include <cmath>
#include <limits>

#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

constexpr double kNsPerMs = 1e6;

// A source value: an exact integer or a real.
struct Value {
  bool real = false;
  __int128 i = 0;
  double r = 0;
};

template <IecType S>
Value read(Cell c) noexcept {
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
    x.i = static_cast<__int128>(v);  // BOOL 0/1, integers, bit strings (unsigned)
  }
  return x;
}

enum class Rounding { Nearest, Trunc };

// The integer a real becomes: nearest (ties to even) or toward zero. The
// inputs are finite (finite_guard.hpp); |r| < 2^127 is checked by the caller.
inline double to_integral(double r, Rounding m) noexcept {
  return m == Rounding::Trunc ? std::trunc(r) : std::nearbyint(r);  // default mode: to nearest, ties to even
}

// Clamps v to [lo, hi]; *out_of_range when it had to.
inline __int128 clamp128(__int128 v, __int128 lo, __int128 hi, bool* out_of_range) noexcept {
  if (v < lo) { *out_of_range = true; return lo; }
  if (v > hi) { *out_of_range = true; return hi; }
  return v;
}

// A real as an integer in [lo, hi] (saturated).
inline __int128 real_to_int(double r, Rounding m, __int128 lo, __int128 hi, bool* out_of_range) noexcept {
  const double q = to_integral(r, m);
  if (q < static_cast<double>(lo)) { *out_of_range = true; return lo; }
  if (q > static_cast<double>(hi)) { *out_of_range = true; return hi; }
  // |q| <= 2^64 here, exact in __int128; double(hi) may round up (2^64 - 1 -> 2^64).
  return clamp128(static_cast<__int128>(q), lo, hi, out_of_range);
}

template <IecType S, IecType D>
Cell convert(Cell in, Rounding m, bool* out_of_range) noexcept {
  using DV = native_t<D>;
  const Value x = read<S>(in);
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
    constexpr auto lo = static_cast<__int128>(std::numeric_limits<std::int64_t>::min());
    constexpr auto hi = static_cast<__int128>(std::numeric_limits<std::int64_t>::max());
    __int128 ns;
    if (x.real) {
      const double q = std::nearbyint(x.r * kNsPerMs);
      ns = q < -9.2e18 ? lo : q > 9.2e18 ? hi : static_cast<__int128>(q);
      if (q < -9.2e18 || q > 9.2e18) *out_of_range = true;
    } else {
      ns = clamp128(x.i * 1'000'000, lo, hi, out_of_range);
    }
    out.set<std::int64_t>(static_cast<std::int64_t>(ns));
  } else if constexpr (type_in_class(D, TypeClass::ANY_BIT)) {
    // The low bits of the two's-complement pattern.
    using U = DV;
    constexpr __int128 umax = static_cast<__int128>(std::numeric_limits<U>::max());
    const __int128 v = x.real ? real_to_int(x.r, m, 0, umax, out_of_range) : x.i;
    out.set<U>(static_cast<U>(static_cast<unsigned __int128>(v)));
  } else {  // a signed or unsigned integer
    constexpr auto lo = static_cast<__int128>(std::numeric_limits<DV>::min());
    constexpr auto hi = static_cast<__int128>(std::numeric_limits<DV>::max());
    if constexpr (type_in_class(S, TypeClass::ANY_BIT) && S != IecType::BOOL && sizeof(native_t<S>) == sizeof(DV)) {
      out.set<DV>(static_cast<DV>(in.get<native_t<S>>()));  // same width: the bits, reinterpreted
    } else if (x.real) {
      out.set<DV>(static_cast<DV>(real_to_int(x.r, m, lo, hi, out_of_range)));
    } else {
      out.set<DV>(static_cast<DV>(clamp128(x.i, lo, hi, out_of_range)));
    }
  }
  return out;
}

template <IecType S, IecType D>
class Conversion final : public Block {
 public:
  explicit Conversion(Rounding m) : m_(m) {}
  void execute(ScanContext& ctx) noexcept override {
    bool out_of_range = false;
    const Cell in = *pin_cell(0);
    *pin_cell(1) = convert<S, D>(in, m_, &out_of_range);
    if (out_of_range) ctx.fault("conversion out of range", cell_as_double(S, in));
  }

 private:
  Rounding m_;
};

constexpr IecType kAll[] = {IecType::BOOL,  IecType::SINT,  IecType::INT,   IecType::DINT,
                            IecType::LINT,  IecType::USINT, IecType::UINT,  IecType::UDINT,
                            IecType::ULINT, IecType::BYTE,  IecType::WORD,  IecType::DWORD,
                            IecType::LWORD, IecType::REAL,  IecType::LREAL, IecType::TIME};

std::string rule_text(IecType s, IecType d, bool trunc) {
  const auto sn = std::string(type_name(s)), dn = std::string(type_name(d));
  std::string t = "OUT := IN converted from " + sn + " to " + dn + ". ";
  if (trunc) return t + "Rounds toward zero (IEC 61131-3 Table 22 note c); a result outside the range of " + dn +
                    " is saturated to its minimum or maximum and raises a block-fault event \"conversion out of "
                    "range\".";
  if (d == IecType::BOOL) return t + "TRUE when IN is not zero.";
  if (s == IecType::BOOL) return t + "FALSE gives 0, TRUE gives 1" + (d == IecType::TIME ? " ms." : ".");
  if (is_bit_string(d))
    return t + (is_real(s) ? "IN is rounded to nearest (ties to even); a value outside 0 .. the largest " + dn +
                                 " is saturated and raises a block-fault event \"conversion out of range\"."
                           : "The low bits of IN's two's-complement pattern" +
                                 std::string(s == IecType::TIME ? ", IN counted in milliseconds" : "") +
                                 " (no fault).");
  std::string r;
  if (s == IecType::TIME) r += "IN counted in milliseconds. ";
  if (d == IecType::TIME) r += "IN counts milliseconds. ";
  if (is_bit_string(s) && is_integer(d) && bit_width(s) == bit_width(d))
    return t + "The bits of IN, reinterpreted (16#FF.. gives -1 for a signed type; no fault).";
  if ((is_real(s) || s == IecType::TIME) && is_integer(d))
    r += "Rounds to nearest, ties to even (IEC 60559, Table 22 note b: 2.5 -> 2, -1.5 -> -2; use " +
         std::string(is_real(s) ? sn + "_TRUNC_" + dn : "a TRUNC") + " to truncate). ";
  if (is_bit_string(s)) r += "IN counts as an unsigned number. ";
  if (d == IecType::LREAL || (d == IecType::REAL && s != IecType::LREAL)) return t + r + "Never out of range.";
  return t + r + "A value outside the range of " + dn +
         " is saturated to its minimum or maximum and raises a block-fault event \"conversion out of range\" "
         "(IEC leaves it implementation-defined; CODESYS keeps the low bits).";
}

BlockTypeInfo info(IecType s, IecType d, bool trunc) {
  BlockTypeInfo t;
  t.name = std::string(type_name(s)) + (trunc ? "_TRUNC_" : "_TO_") + std::string(type_name(d));
  t.category = "IEC type conversion";
  t.doc = rule_text(s, d, trunc);
  t.reference = trunc ? "IEC 61131-3 standard function, 2.5.1.5.1 Table 22 note c (typed *_TRUNC_** of ed. 3)"
                      : "IEC 61131-3 standard function, 2.5.1.5.1 Table 22 (type conversion), notes a and b";
  t.pins = {input("IN", s).required().doc("value to convert"),
            output("OUT", d).doc("IN as " + std::string(type_name(d)))};
  return t;
}

}  // namespace

void register_conversions(BlockRegistry& r) {
  for (IecType s : kAll)
    for (IecType d : kAll) {
      if (s == d) continue;
      for (bool trunc : {false, true}) {
        if (trunc && !(is_real(s) && is_integer(d))) continue;
        BlockTypeInfo t = info(s, d, trunc);
        const Rounding m = trunc ? Rounding::Trunc : Rounding::Nearest;
        t.create = [s, d, m](BlockSetup&) -> std::unique_ptr<Block> {
          return dispatch_type(s, [&]<IecType S>() -> std::unique_ptr<Block> {
            return dispatch_type(d, [&]<IecType D>() -> std::unique_ptr<Block> {
              if constexpr (S == D) return nullptr;
              else return std::make_unique<Conversion<S, D>>(m);
            });
          });
        };
        r.add(std::move(t));
      }
    }
}

}  // namespace syncplc::iec
