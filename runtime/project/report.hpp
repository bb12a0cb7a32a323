// Human-readable reports of a loaded program: the task table, execution
// orders, the tag map, and per-task statistics after a run.
#pragma once

#include <ostream>

#include "runtime/core/program.hpp"

namespace syncplc {

void print_task_table(std::ostream& os, const Program& p);
void print_execution_order(std::ostream& os, const Program& p);
void print_tag_map(std::ostream& os, const Program& p);
void print_statistics(std::ostream& os, const Program& p, bool virtual_time);
// Every driver's IoDriver::counters(), those named "<what>.<counter>" one line
// per <what>: "    g: requests=1000 errors=0 ...". Nothing for drivers without counters.
void print_driver_counters(std::ostream& os, const Program& p);
// Drains every task's event ring and prints the events. Returns how many.
std::size_t print_events(std::ostream& os, Program& p);
std::string format_event(const Program& p, const Event& e);
// The same line for an event of `where` (a task's name; the supervisor's events).
std::string format_event(const std::string& where, const Event& e);
// What an event's value means, as format_event appends it: " (scan took 1.2ms)", or "".
std::string event_value_text(const Event& e);
std::string format_ns(std::int64_t ns);  // 1.234ms, 12us, 3.5s

}  // namespace syncplc
