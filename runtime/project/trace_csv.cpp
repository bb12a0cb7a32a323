#include "runtime/project/trace_csv.hpp"

#include <fmt/format.h>

namespace syncplc {

std::string format_trace_value(IecType t, Cell c) {
  return dispatch_type(t, [&]<IecType T>() -> std::string {
    using N = typename Native<T>::type;
    N v = c.get<N>();
    if constexpr (T == IecType::BOOL) return v ? "1" : "0";
    else if constexpr (T == IecType::TIME) return fmt::format("{:.9f}", static_cast<double>(v) * 1e-9);
    else if constexpr (std::is_floating_point_v<N>) return fmt::format("{}", v);  // shortest round-trip
    else return fmt::format("{}", v);
  });
}

void write_trace_header(std::ostream& os, const Program& p) {
  os << "time_s";
  for (const auto& c : p.traces) os << ',' << c.label;
  os << '\n';
}

void write_trace_row(std::ostream& os, const Program& p, ImageAccess a, std::int64_t time_ns) {
  os << fmt::format("{:.9f}", static_cast<double>(time_ns) * 1e-9);
  for (const auto& c : p.traces) os << ',' << format_trace_value(c.ref.type, *p.live_cell(c.ref, a));
  os << '\n';
}

}  // namespace syncplc
