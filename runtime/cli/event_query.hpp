// Reading the event log (docs/store.md, "syncplc events"): which events,
// from when, and one line each. Works on a read-only connection, also while
// `syncplc run` writes the database (WAL).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/store/log_queries.hpp"

namespace syncplc::cli {

// --since: a duration back from now ("10m", "2h", "90s") or a local time
// ("2026-11-25T10:00:00", "2026-11-25 10:00", "2026-11-25"). Wall time in ns
// since 1970; nullopt with `error` when it is neither.
std::optional<std::int64_t> parse_since(const std::string& text, std::int64_t wall_now_ns, std::string* error);

// The events themselves: runtime/store/log_queries.hpp.
using store::EventFilter;
using store::LoggedEvent;
using store::read_events;

// "2026-11-25 10:00:00.123  hmi-write      main     scan -  speed := 12.5  client 127.0.0.1:40512",
// local time; a message of several lines continues indented.
std::string format_logged_event(const LoggedEvent& e);

}  // namespace syncplc::cli
