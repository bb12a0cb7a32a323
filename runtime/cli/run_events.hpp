// What `syncplc run` records in the event log (docs/store.md, "The event
// log"): its start and stop, reloads, the tasks' and the supervisor's events
// with their wall time, task and scan, and, as the Modbus server's audit
// trail, every write an HMI made with its address and every refused
// connection. Everything goes through PlcStore::record (a bounded queue the
// store thread empties); nothing here runs on a task thread.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "runtime/cli/plc_store.hpp"
#include "runtime/core/block.hpp"
#include "runtime/core/program.hpp"
#include "runtime/modbus/audit.hpp"

namespace syncplc::cli {

class RunEvents : public modbus::ServerAudit {
 public:
  explicit RunEvents(PlcStore& store) : store_(store) {}

  // The tasks' time axis starts at `epoch_monotonic_ns` (RealtimeRunner::
  // epoch_ns): from then on events' times convert to wall time.
  void set_epoch(std::int64_t epoch_monotonic_ns);
  // CLOCK_REALTIME at the tasks' time 0 (0 before set_epoch): a scan's
  // planned release in wall time is this plus its logical time.
  std::int64_t wall_at_epoch_ns() const { return wall_at_epoch_ns_; }

  void started(const std::string& project, const std::string& database);
  void stopped(const std::string& why);
  // The project loaded but the PLC did not start (a driver that did not open,
  // a Modbus port in use): why, and the exit status.
  void start_failed(const std::string& why);
  void reloaded(bool accepted, const std::string& summary, const std::vector<std::string>& lines);
  // A task's or the supervisor's event, from `p` (the program that raised it).
  void task_event(const Program& p, const Event& e);

  // modbus::ServerAudit, on the server thread.
  void written(const Program& program, modbus::ClientAddress client, const ModbusPoint* const* points,
               const QueuedWrite* values, std::size_t n) override;
  void refused(modbus::ClientAddress client, const char* why) override;

 private:
  PlcStore& store_;
  std::int64_t wall_at_epoch_ns_ = 0;  // CLOCK_REALTIME at the tasks' time 0
};

// Prints every queued event of p's tasks to `os` (as run prints them) and
// records each in `log` when it is not null.
void drain_task_events(std::ostream& os, Program& p, RunEvents* log);

}  // namespace syncplc::cli
