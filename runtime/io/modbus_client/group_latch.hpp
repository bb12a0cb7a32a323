// The scan side of one request group: what latch_inputs makes of the newest
// result. Pure logic over (result, now), so tests drive it in virtual time.
//
// - A successful result: the values are taken, ok TRUE; after a fault, a
//   recovery event.
// - A failed result (timeout, lost connection, bad reply, exception): ok
//   FALSE at once, the values are stale from this scan on; a fault event for
//   every new error code. The stale time starts.
// - Stale for stale_after (measured from the first failed result): the
//   group's reaction, once per stale period, with an event: hold (the last
//   values stay, flagged by ok FALSE and reaction TRUE), safe (the inputs
//   take the group's safe values while stale), stop (the task is asked to
//   stop with its safe outputs, ScanContext::request_stop).
// - Before the first result the group is not ok (error 268, no reply yet) and
//   the stale time has not started: the first exchange or connection attempt
//   ends within connect_timeout + response_timeout.
//
// Age of data: now minus the completion of the last successful exchange (or
// minus open() before the first), in ms; and in scans (`cycles`): the scans'
// hand-over count now minus the count when the request of the values shown
// was sent (or minus the count at open() before the first), so 0 means the
// values come from the reply to this cycle's request (timing cycle: the
// exchange after the previous scan's hand-over), n that they are n scans old.
#pragma once

#include <array>
#include <cstdint>

#include "runtime/core/block.hpp"
#include "runtime/io/modbus_client/client_config.hpp"

namespace syncplc {

// The events' static texts of one group ("modbus_client io.temps: timeout"),
// built (interned for the life of the process) before the first scan.
struct GroupTexts {
  std::array<const char*, kErrorSlots> fault{};
  const char* recovered = "";
  const char* reaction = "";
};
GroupTexts make_group_texts(const std::string& driver, const RequestGroup& g);
// A copy of `text` that lives as long as the process (events keep the pointer).
const char* intern_text(const std::string& text);

struct GroupStatus {
  bool ok = false;
  bool reacting = false;     // stale for stale_after: the reaction applies
  std::uint16_t error = code(ClientError::NoReply);
  double age_ms = 0;
  bool fresh = false;        // this latch took new values (copy them to the channel)
  std::int64_t sent = 0;     // when fresh: the request of those values was sent (driver clock)
  std::uint32_t cycles = 0;  // scans since the request of the values shown was handed over
  std::uint64_t epoch = 0;   // the connection of the values shown while ok; 0 when not ok
};

class GroupLatch {
 public:
  GroupLatch() = default;
  GroupLatch(const RequestGroup& g, GroupTexts texts) : g_(&g), texts_(texts) {}
  void reset(std::int64_t open_ns, std::uint32_t open_cycle = 0) noexcept;
  // result: the group's results buffer (GroupHandover layout). Values of a
  // successful result are copied to `values` (read_values() cells). cycle:
  // the scans' hand-over count now.
  const GroupStatus& latch(const Cell* result, std::int64_t now, const ScanContext& ctx, Cell* values,
                           std::uint32_t cycle = 0) noexcept;
  const GroupStatus& status() const noexcept { return st_; }
  bool stale() const noexcept { return stale_; }

 private:
  void raise(const ScanContext& ctx, EventKind kind, const char* text, double value) noexcept;

  const RequestGroup* g_ = nullptr;
  GroupTexts texts_;
  GroupStatus st_;
  std::uint64_t seen_ = 0;        // seq of the last result taken
  bool stale_ = false;            // a failure since the last success
  std::int64_t stale_since_ = 0;
  std::int64_t last_ok_ = 0;      // completion of the last success (or open)
  std::uint32_t shown_cycle_ = 0; // the hand-over count the shown values' request was sent at (or open's)
  bool reacted_ = false;
};

}  // namespace syncplc
