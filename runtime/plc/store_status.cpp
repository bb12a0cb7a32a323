#include "runtime/plc/store_status.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "runtime/core/monotonic_clock.hpp"

namespace syncplc::plc {

StoreStatus store_status(const StoreLink& s) {
  StoreStatus st;
  const store::StoreHealth h = s.health();
  st.error = h.last_error;
  st.failures = h.failures;
  st.pending = s.events().pending();
  st.dropped = s.events().dropped();
  st.trend_lost = s.trend_buckets_lost();
  if (h.last_ok_ns > 0) st.since_ok_ns = monotonic_ns() - h.last_ok_ns;
  st.state = s.read_only() ? StoreStatus::State::ReadOnly
             : !s.on()      ? StoreStatus::State::Off
             : h.fault      ? StoreStatus::State::Fault
                            : StoreStatus::State::Ok;
  return st;
}

const char* store_state_name(StoreStatus::State s) {
  switch (s) {
    case StoreStatus::State::Ok: return "ok";
    case StoreStatus::State::Fault: return "FAULT";
    case StoreStatus::State::Off: return "off";
    case StoreStatus::State::ReadOnly: return "read-only";
  }
  return "?";
}

std::string store_status_line(const StoreStatus& st, const std::string& path) {
  std::string line;
  switch (st.state) {
    case StoreStatus::State::Ok:
      line = fmt::format("Store ok  {}", std::filesystem::path(path).filename().string());
      if (st.dropped) line += fmt::format("  {} events dropped", st.dropped);
      if (st.trend_lost) line += fmt::format("  {} trend buckets lost", st.trend_lost);
      break;
    case StoreStatus::State::Fault:
      // The counts first: the error text is cut at the screen's edge.
      line = fmt::format("Store FAULT  {} pending  {} failures  {}", st.pending, st.failures, st.error);
      break;
    case StoreStatus::State::Off: line = "Store off  " + st.error; break;
    case StoreStatus::State::ReadOnly:
      line = fmt::format("Store READ-ONLY  {}  nothing recorded: {}", std::filesystem::path(path).filename().string(), st.error);
      break;
  }
  return line;
}

void print_store_status(std::ostream& os, const StoreLink& s) {
  const StoreStatus st = store_status(s);
  switch (st.state) {
    case StoreStatus::State::Ok:
      if (!st.dropped && !st.trend_lost) return;  // all is well: nothing to add to the statistics
      os << "\nStore: ok, " << s.path() << "\n";
      break;
    case StoreStatus::State::Fault:
      os << "\nStore: FAULT: " << st.error << "; " << st.pending << " event records were not written (" << st.failures
         << " failed attempts)\n";
      break;
    case StoreStatus::State::Off:
      os << "\nStore: off (" << st.error << "): nothing was recorded\n";
      return;
    case StoreStatus::State::ReadOnly:
      os << "\nStore: READ-ONLY, " << s.path() << " (" << st.error << "): retained values were restored from it, nothing was recorded\n";
      return;
  }
  if (st.dropped) os << "  " << st.dropped << " event records dropped (the queue of " << s.events().capacity() << " was full)\n";
  if (st.trend_lost)
    os << "  " << st.trend_lost << " trend buckets lost (a task's ring or the historian's queue was full; docs/store.md)\n";
}

modbus::StoreStatusWords store_status_words(const StoreStatus& st) {
  auto u32 = [](std::uint64_t v) { return static_cast<std::uint32_t>(std::min<std::uint64_t>(v, 0xFFFFFFFF)); };
  modbus::StoreStatusWords w;
  w.state = static_cast<std::uint16_t>(st.state);
  w.since_ok_s = st.since_ok_ns < 0 ? 0xFFFF : static_cast<std::uint16_t>(std::min<std::int64_t>(st.since_ok_ns / 1'000'000'000, 0xFFFE));
  w.pending = u32(st.pending);
  w.dropped = u32(st.dropped + st.trend_lost);
  w.failures = u32(st.failures);
  return w;
}

modbus::StoreStatusWords StoreStatusRegisters::store_status_words() const { return plc::store_status_words(store_status(store_)); }

}  // namespace syncplc::plc
