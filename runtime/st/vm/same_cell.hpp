// Whether two engines' cells agree (docs/st.md, "How compiled ST runs"):
// equal bits, or two NaNs (an LREAL's, or a REAL's in the low half of a
// cell whose high half is zero). Which operand's NaN an operation on two
// NaNs passes on is the C++ compiler's choice of operand order in the
// interpreter (IEEE 754 leaves it open): the one place the engines may
// differ. For the differential tests and the engines' fuzzer.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace syncplc::st::vm {

inline bool same_cell(std::uint64_t a, std::uint64_t b) {
  if (a == b) return true;
  double da, db;
  std::memcpy(&da, &a, 8);
  std::memcpy(&db, &b, 8);
  if (std::isnan(da) && std::isnan(db)) return true;
  if ((a >> 32) != 0 || (b >> 32) != 0) return false;
  float fa, fb;
  const auto la = static_cast<std::uint32_t>(a), lb = static_cast<std::uint32_t>(b);
  std::memcpy(&fa, &la, 4);
  std::memcpy(&fb, &lb, 4);
  return std::isnan(fa) && std::isnan(fb);
}

}  // namespace syncplc::st::vm
