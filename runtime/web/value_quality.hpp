// The quality of a live value as the HTTP API shows it (docs/http-api.md,
// "Quality of a live value"): whether an operator may take it as the
// machine's state now. One value, one word, the worst that applies:
//
//   task_stopped   its task does not run (stopped by its watchdog, a
//                  driver's reaction or the supervisor; the PLC not started
//                  or stopping): the value will not change again
//   stale          its task has published nothing newer for three periods
//                  and a tenth of a second (a scan that does not end, a
//                  task starved), or no scan has produced it yet
//   driver_not_ok  a tag bound to a driver's input channel whose exchange
//                  failed (modbus_client: the read group's ok is FALSE):
//                  the last good value, or the group's safe value
//   forced         held by a force, not by the program
//   good           none of these
//
// With it goes the logical time of the scan that produced the value (the
// release of that scan on the tasks' time axis, GET /status's
// epoch_wall_ns is its wall time) and its age when it was read.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "runtime/core/io_driver.hpp"
#include "runtime/core/program.hpp"

namespace syncplc::web {

enum class Quality : std::uint8_t { Good, Forced, DriverNotOk, Stale, TaskStopped };
const char* quality_name(Quality q);

// How long a value may go without a newer publication of its task before it
// is stale: three periods (an overrun or two is not yet a hang) and a tenth
// of a second (the HMI's update interval: an operator cannot see less, and
// a task thread woken late by a busy kernel is not flagged).
inline constexpr std::int64_t kStaleSlackNs = 100'000'000;
inline std::int64_t stale_after_ns(std::int64_t period_ns) { return 3 * period_ns + kStaleSlackNs; }

// What the rule looks at, read with the program held.
struct QualityInputs {
  bool task_stopped = false;    // Task::stopped(), or no scheduler runs the program
  ValueStamp stamp;             // Program::read_value's
  std::int64_t now_ns = -1;     // logical time now (read before the value), -1: unknown
  std::int64_t period_ns = 0;   // the owning task's
  bool driver_ok = true;        // IoDriver::input_ok of the channel bound to the tag
  bool forced = false;          // any element forced
};

struct ValueQuality {
  Quality quality = Quality::Good;
  std::int64_t age_ns = 0;  // now - the scan's release (0 when now is unknown or before it)
};
ValueQuality judge_value(const QualityInputs& in);

// Where a reference's value comes from: its cell, its task, and the driver
// input channel bound to it (a tag or an element of one; null for pins and
// tags no driver writes). Found once per program (the pointers live as long
// as the program).
struct ValueSource {
  CellRef cell;
  const Task* task = nullptr;
  const IoDriver* driver = nullptr;
  int channel = -1;
};
// nullopt with *why for an unknown reference.
std::optional<ValueSource> value_source(const Program& p, const std::string& ref, std::string* why);

}  // namespace syncplc::web
