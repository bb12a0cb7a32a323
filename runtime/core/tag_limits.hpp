// A tag's engineering limits (docs/project-format.md, tag keys `min` and
// `max`): a setpoint's range as the plant allows it, narrower than its
// type's. The loader checks the tag's own values against them; the HTTP
// API (and so the HMI) and the Modbus server refuse a write outside them.
#pragma once

#include <string>

#include "runtime/core/program.hpp"

namespace syncplc {

// "" when `v` (one element of `t`'s type) is within t's limits, else why
// not, e.g. "1e+39 is above speed's max 100 (its engineering limit)". A
// NaN is outside any limit.
std::string outside_limits(const Tag& t, Cell v);
// The same test without the words (the Modbus server's write path: no allocation).
bool within_limits(const Tag& t, Cell v) noexcept;

}  // namespace syncplc
