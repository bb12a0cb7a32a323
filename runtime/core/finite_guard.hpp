// The finite-input rule (IEC 61131-3 ENO) and the tuning inputs, applied
// around every block's execute() by Task::scan and by the BlockHarness.
//
// Before a block executes (after its inputs were copied in):
//   1. each connected tuning input <param>_in that changed since the last scan
//      is validated (finite, within the ParamDecl range, accepted by
//      Block::tune): a valid value takes effect bumplessly; an invalid one is
//      refused, the last valid value stays, ENO is FALSE and a block-fault
//      event "tuning input invalid" is raised while the pin stays invalid. The
//      block still executes, on its last valid parameters (IEC: ENO FALSE
//      reports an error; the outputs are those of the last valid tuning).
//   2. every REAL/LREAL input element is checked: if one is NaN or infinite
//      the block does not execute, ENO is FALSE, and a block-fault event
//      "input not finite" carries the value (the task reports it once per
//      series of faulting scans). The outputs keep their last valid values
//      (the task still copies them out), the state is untouched, and the block
//      runs normally again from the first scan its inputs are finite.
// A unit delay reads its input at end_of_scan, so there the check guards
// end_of_scan: the held value is kept and ENO is FALSE on the next scan.
//
// BlockGuard (block.hpp) is sized when the instance is created; nothing here
// allocates, locks or logs.
#pragma once

#include <cmath>

#include "runtime/core/block.hpp"

namespace syncplc {

// True when no element of c[0..n) is a NaN or an infinity, i.e. its exponent
// bits are not all ones (IEEE 754; a REAL's bits are the low 32 of its cell).
// The exponent field plus its lowest bit carries into the bit above the field
// (bit 63, or 31 for REAL) exactly when the field is all ones, and an OR of
// values below that bit stays below it: four instructions per element and no
// branch (the check runs over every array input of every block, every scan).
inline bool cells_finite(const Cell* c, std::uint32_t n, bool single) noexcept {
  const std::uint64_t exp = single ? 0x7f800000ull : 0x7ff0000000000000ull;
  const std::uint64_t low = exp & (~exp + 1);  // the field's lowest bit
  std::uint64_t a0 = 0, a1 = 0;
  std::uint32_t k = 0;
  for (; k + 2 <= n; k += 2) {
    a0 |= (c[k].raw & exp) + low;
    a1 |= (c[k + 1].raw & exp) + low;
  }
  if (k < n) a0 |= (c[k].raw & exp) + low;
  return ((a0 | a1) & (exp + low)) == 0;
}

// True when every REAL/LREAL input element of `b` is finite; else *bad is the
// first value that is not.
inline bool inputs_finite(const Block& b, double* bad) noexcept {
  for (const auto& s : b.guard().reals) {
    const Cell* c = b.pin_cell(s.pin);
    if (cells_finite(c, s.n, s.single)) continue;
    for (std::uint32_t k = 0; k < s.n; ++k) {
      const double v = s.single ? static_cast<double>(c[k].get<float>()) : c[k].get<double>();
      if (!std::isfinite(v)) {
        *bad = v;
        return false;
      }
    }
  }
  return true;
}

// Step 1 above: false when a tuning input is invalid (ENO must be FALSE).
inline bool apply_tuning(Block& b, ScanContext& ctx) noexcept {
  bool ok = true;
  for (auto& t : b.guard().tuning) {
    const double v = cell_as_double(t.type, *b.pin_cell(t.pin));
    const bool same = v == t.seen || (std::isnan(v) && std::isnan(t.seen));
    if (!same) {
      t.seen = v;
      t.ok = std::isfinite(v) && v >= t.min && v <= t.max && b.tune(t.param, v);
    }
    if (!t.ok) {
      ctx.fault("tuning input invalid, last valid value kept", v);
      ok = false;
    }
  }
  return ok;
}

inline void write_eno(Block& b, bool eno) noexcept {
  if (b.guard().eno >= 0) b.pin_cell(b.guard().eno)->set<bool>(eno);
}

// execute() under the finite-input rule.
inline void execute_guarded(Block& b, ScanContext& ctx) noexcept {
  BlockGuard& g = b.guard();
  bool eno = g.tuning.empty() || apply_tuning(b, ctx);
  if (!g.unit_delay) {
    double bad = 0;
    if (!inputs_finite(b, &bad)) {
      ctx.fault("input not finite", bad);
      write_eno(b, false);
      return;
    }
  } else if (g.held) {
    eno = false;
  }
  b.execute(ctx);
  write_eno(b, eno);
}

// end_of_scan() under the finite-input rule (unit delays).
inline void end_of_scan_guarded(Block& b, ScanContext& ctx) noexcept {
  BlockGuard& g = b.guard();
  double bad = 0;
  if (g.unit_delay && !inputs_finite(b, &bad)) {
    ctx.fault("input not finite", bad);
    g.held = true;
    return;
  }
  g.held = false;
  b.end_of_scan();
}

}  // namespace syncplc
