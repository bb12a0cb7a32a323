// What the Modbus server has done, for `syncplc run`'s statistics and tests.
// Written by the server thread only; read by anyone (relaxed atomics).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <ostream>

namespace syncplc::modbus {

struct Counters {
  std::atomic<std::uint64_t> requests{0};     // whole frames answered or being answered
  std::atomic<std::uint64_t> exceptions{0};   // exception responses sent
  std::array<std::atomic<std::uint64_t>, 12> by_exception{};  // index: exception code 1..11
  std::atomic<std::uint64_t> values_written{0};  // values queued for tasks
  std::atomic<std::uint64_t> accepted{0};     // connections taken on
  std::atomic<std::uint64_t> refused{0};      // closed at once: over max_clients or not an allowed client
  std::atomic<std::uint64_t> open{0};         // connections open now
  std::atomic<std::uint64_t> closed_by_peer{0};
  std::atomic<std::uint64_t> closed_bad_frame{0};  // not Modbus TCP (protocol id, length)
  std::atomic<std::uint64_t> closed_idle{0};       // no whole request within idle_timeout
  std::atomic<std::uint64_t> closed_unsendable{0};  // a reply could not be sent whole (client not reading)

  struct Summary {
    std::uint64_t requests, exceptions, values_written, accepted, refused, open, closed_by_peer, closed_bad_frame,
        closed_idle, closed_unsendable;
    std::array<std::uint64_t, 12> by_exception;
  };
  Summary summary() const;
  void count_exception(int code) {
    exceptions.fetch_add(1, std::memory_order_relaxed);
    if (code > 0 && code < 12) by_exception[static_cast<std::size_t>(code)].fetch_add(1, std::memory_order_relaxed);
  }
};

// "Modbus: 1234 requests, 5 exceptions (02: 3, 03: 2), ..." in one or two lines.
void print_counters(std::ostream& os, const Counters::Summary& s);

}  // namespace syncplc::modbus
