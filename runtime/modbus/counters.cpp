#include "runtime/modbus/counters.hpp"

#include <fmt/format.h>

namespace syncplc::modbus {

Counters::Summary Counters::summary() const {
  auto r = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  Summary s{r(requests), r(exceptions), r(values_written), r(accepted), r(refused), r(open),
            r(closed_by_peer), r(closed_bad_frame), r(closed_idle), r(closed_unsendable), {}};
  for (std::size_t i = 0; i < by_exception.size(); ++i) s.by_exception[i] = r(by_exception[i]);
  return s;
}

void print_counters(std::ostream& os, const Counters::Summary& s) {
  std::string codes;
  for (std::size_t i = 1; i < s.by_exception.size(); ++i)
    if (s.by_exception[i]) codes += fmt::format("{}{:02X}: {}", codes.empty() ? "" : ", ", i, s.by_exception[i]);
  os << fmt::format("  requests {}, exceptions {}{}, values written {}\n", s.requests, s.exceptions,
                    codes.empty() ? "" : " (" + codes + ")", s.values_written);
  os << fmt::format("  connections: {} accepted, {} refused, {} open; closed: {} by the client, {} bad frame, "
                    "{} idle, {} not reading\n",
                    s.accepted, s.refused, s.open, s.closed_by_peer, s.closed_bad_frame, s.closed_idle,
                    s.closed_unsendable);
}

}  // namespace syncplc::modbus
