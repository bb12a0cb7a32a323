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

}  // namespace syncplc
