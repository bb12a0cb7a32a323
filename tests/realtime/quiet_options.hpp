// Real-time runner options for tests: normal priority (tests must not compete
// with the machine's own real-time work), no memory locking, a short start
// delay, CPU idle states left alone.
#pragma once

#include "runtime/core/realtime.hpp"

namespace syncplc {

inline RealtimeRunner::Options quiet_options() {
  RealtimeRunner::Options o;
  o.fifo = false;
  o.lock_memory = false;
  o.start_delay_ns = 1'000'000;
  o.cpu_latency_us = -1;
  return o;
}

}  // namespace syncplc
