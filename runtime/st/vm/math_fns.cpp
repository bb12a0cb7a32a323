// The VM's numeric library functions (math_fns.hpp).
#include "runtime/st/vm/math_fns.hpp"

#include <cmath>
#include <limits>

#include "runtime/st/types.hpp"

namespace syncplc::st::vm {

namespace {

template <class T, T (*F)(T)>
Cell unary(Cell in) noexcept {
  Cell out;
  out.set<T>(F(in.get<T>()));
  return out;
}

template <class T, T (*F)(T, T)>
Cell binary(Cell a, Cell b) noexcept {
  Cell out;
  out.set<T>(F(a.get<T>(), b.get<T>()));
  return out;
}

// The overloads of <cmath> as plain functions of one type (addressable).
template <class T> T f_sqrt(T x) { return std::sqrt(x); }
template <class T> T f_ln(T x) { return std::log(x); }
template <class T> T f_log(T x) { return std::log10(x); }
template <class T> T f_exp(T x) { return std::exp(x); }
template <class T> T f_sin(T x) { return std::sin(x); }
template <class T> T f_cos(T x) { return std::cos(x); }
template <class T> T f_tan(T x) { return std::tan(x); }
template <class T> T f_asin(T x) { return std::asin(x); }
template <class T> T f_acos(T x) { return std::acos(x); }
template <class T> T f_atan(T x) { return std::atan(x); }
template <class T> T f_atan2(T y, T x) { return std::atan2(y, x); }
template <class T> T f_pow(T x, T y) { return std::pow(x, y); }

template <class T>
Math1Fn pick1(std::string_view n) {
  if (same_name(n, "SQRT")) return unary<T, f_sqrt<T>>;
  if (same_name(n, "LN")) return unary<T, f_ln<T>>;
  if (same_name(n, "LOG")) return unary<T, f_log<T>>;
  if (same_name(n, "EXP")) return unary<T, f_exp<T>>;
  if (same_name(n, "SIN")) return unary<T, f_sin<T>>;
  if (same_name(n, "COS")) return unary<T, f_cos<T>>;
  if (same_name(n, "TAN")) return unary<T, f_tan<T>>;
  if (same_name(n, "ASIN")) return unary<T, f_asin<T>>;
  if (same_name(n, "ACOS")) return unary<T, f_acos<T>>;
  if (same_name(n, "ATAN")) return unary<T, f_atan<T>>;
  return nullptr;
}

std::int64_t saturate_ns(double ns) noexcept {
  if (std::isnan(ns)) return 0;
  constexpr double hi = 9223372036854775807.0;  // 2^63 as a double
  if (ns >= hi) return std::numeric_limits<std::int64_t>::max();
  if (ns < -hi) return std::numeric_limits<std::int64_t>::min();
  return static_cast<std::int64_t>(std::nearbyint(ns));
}

}  // namespace

Math1Fn math1_fn(std::string_view name, bool lreal) { return lreal ? pick1<double>(name) : pick1<float>(name); }

Math2Fn math2_fn(std::string_view name, bool lreal) {
  if (same_name(name, "ATAN2")) return lreal ? binary<double, f_atan2<double>> : binary<float, f_atan2<float>>;
  if (same_name(name, "EXPT")) return lreal ? binary<double, f_pow<double>> : binary<float, f_pow<float>>;
  return nullptr;
}

Cell time_mul_real(Cell ns, Cell factor) noexcept {
  Cell out;
  out.set<std::int64_t>(saturate_ns(static_cast<double>(ns.get<std::int64_t>()) * factor.get<double>()));
  return out;
}

Cell time_div_real(Cell ns, Cell divisor) noexcept {
  Cell out;
  out.set<std::int64_t>(saturate_ns(static_cast<double>(ns.get<std::int64_t>()) / divisor.get<double>()));
  return out;
}

}  // namespace syncplc::st::vm
