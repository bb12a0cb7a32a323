// Wall-clock instants on the command line and in exports: UTC, ISO 8601.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace syncplc::cli {

// ns since the Unix epoch, now.
std::int64_t wall_now_ns();
// "2026-11-25T04:00:00Z", "2026-11-25 04:00:00.250", "2026-11-25" (UTC), "now",
// or a duration meaning that long before `now_ns` ("10m", "2h").
std::optional<std::int64_t> parse_when(const std::string& text, std::int64_t now_ns, std::string* error);
// "2026-11-25T04:00:00.100Z" (milliseconds).
std::string format_wall(std::int64_t ns);

}  // namespace syncplc::cli
