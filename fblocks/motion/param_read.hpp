// Internal: the checked parameter reads of the controller blocks
// (SYNC_CONTROLLER, PD_CONTROLLER, PID). The block harness does not
// range-check parameters; the loader does, but the factories check again so a
// bad value is a load error from either path.
#pragma once

#include <cmath>
#include <string>

#include "runtime/core/block.hpp"

namespace syncplc::motion::ctl {

// The declaration index of `name`; -1 for a misspelt name in the factory,
// reported as a load error (not as an out-of-range read).
inline int param_index_or_report(BlockSetup& s, const char* name, bool* ok) {
  const int i = s.type().param_index(name);
  if (i < 0) {
    s.unknown_param(name);
    *ok = false;
  }
  return i;
}

// Reads an LREAL parameter; reports a non-finite value or one outside the
// declared range as a load error (returns the value anyway).
inline double real_param(BlockSetup& s, const char* name, bool* ok) {
  const BlockTypeInfo& t = s.type();
  const int i = param_index_or_report(s, name, ok);
  if (i < 0) return 0;
  const ParamDecl& d = t.params[static_cast<std::size_t>(i)];
  const double v = s.param_cell(i).get<double>();
  auto fail = [&](const std::string& why) {
    s.error(t.name + ": parameter " + name + " " + why);
    *ok = false;
  };
  if (!std::isfinite(v)) fail("must be finite");
  else if (d.min && v < *d.min) fail("must be >= " + std::to_string(*d.min));
  else if (d.max && v > *d.max) fail("must be <= " + std::to_string(*d.max));
  return v;
}

// Reads an integer parameter (any IEC integer type) with its declared range.
inline long long int_param(BlockSetup& s, const char* name, bool* ok) {
  const BlockTypeInfo& t = s.type();
  const int i = param_index_or_report(s, name, ok);
  if (i < 0) return 0;
  const ParamDecl& d = t.params[static_cast<std::size_t>(i)];
  const double v = cell_as_double(d.type, s.param_cell(i));
  if ((d.min && v < *d.min) || (d.max && v > *d.max)) {
    s.error(t.name + ": parameter " + name + " must be in " + (d.min ? std::to_string(static_cast<long long>(*d.min)) : "") +
            ".." + (d.max ? std::to_string(static_cast<long long>(*d.max)) : ""));
    *ok = false;
  }
  return static_cast<long long>(v);
}

inline bool bool_param(BlockSetup& s, const char* name) {
  return s.param_cell(s.type().param_index(name)).get<bool>();
}

}  // namespace syncplc::motion::ctl
