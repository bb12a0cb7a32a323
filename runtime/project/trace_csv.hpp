// Writes a program's traced pins as CSV: a time_s column, then one column per
// traced pin or tag, one row per virtual-time instant at which a scan ran.
// Numbers are printed with round-trip precision, so two runs of the same
// project and seed give byte-identical files.
#pragma once

#include <ostream>

#include "runtime/core/program.hpp"

namespace syncplc {

void write_trace_header(std::ostream& os, const Program& p);
// In virtual time: `a` is the clock's (image_access.hpp).
void write_trace_row(std::ostream& os, const Program& p, ImageAccess a, std::int64_t time_ns);
std::string format_trace_value(IecType t, Cell c);

}  // namespace syncplc
