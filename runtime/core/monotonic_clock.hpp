// The one monotonic clock of the runtime, in nanoseconds: real-time release
// deadlines (CLOCK_MONOTONIC, as clock_nanosleep uses), the Modbus server's
// idle timeouts, wall-clock measurements.
#pragma once

#include <time.h>

#include <cstdint>

namespace syncplc {

inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// CLOCK_REALTIME in ns since the Unix epoch: the clock nodes on several
// machines share (disciplined by PTP/NTP); used only to anchor the tasks'
// grid (RealtimeRunner::Options::align_ns) and to stamp samples.
inline std::int64_t realtime_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace syncplc
