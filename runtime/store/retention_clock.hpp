// The store's wall clock, as its jobs read it: injectable, so that a test
// can step it (docs/store.md, "Age limits and the wall clock").
#pragma once

#include <cstdint>
#include <functional>

namespace syncplc::store {

// ns since 1970 (UTC); by default CLOCK_REALTIME (wall_now_ns(), event_log.hpp).
using WallClock = std::function<std::int64_t()>;

}  // namespace syncplc::store
