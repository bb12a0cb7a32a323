// What the PLC records in the event log (docs/store.md, "The event
// log"): its start and stop, reloads, the tasks' and the supervisor's events
// with their wall time, task and scan, and, as the Modbus server's audit
// trail, every write an HMI made with its address and every refused
// connection. Everything goes through StoreLink::record (a bounded queue the
// store thread empties); nothing here runs on a task thread.
#pragma once

#include <cstdint>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "runtime/plc/store_link.hpp"
#include "runtime/core/block.hpp"
#include "runtime/core/program.hpp"
#include "runtime/modbus/audit.hpp"
#include "runtime/plc/transaction.hpp"

namespace syncplc::plc {

class EventRecorder : public modbus::ServerAudit {
 public:
  explicit EventRecorder(StoreLink& store) : store_(store) {}

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
  // An event of the supervisor's about the task named `task`.
  void task_event(const std::string& task, const Event& e);

  // modbus::ServerAudit, on the server thread.
  void written(const Program& program, modbus::ClientAddress client, const ModbusPoint* const* points,
               const QueuedWrite* values, std::size_t n) override;
  void refused(modbus::ClientAddress client, const char* why) override;

 private:
  void record_task_event(const std::string& task, const std::string& source, const Event& e);
  StoreLink& store_;
  std::int64_t wall_at_epoch_ns_ = 0;  // CLOCK_REALTIME at the tasks' time 0
};

// The events' part in an online change: at completion, the old program's
// tasks' last events are routed (printed and recorded) before it goes.
class EventsChange final : public ChangeParticipant {
 public:
  explicit EventsChange(std::function<void(Program&)> route) : route_(std::move(route)) {}
  const char* name() const override { return "events"; }
  void complete(ChangeContext& c) override { route_(c.from); }

 private:
  std::function<void(Program&)> route_;
};

}  // namespace syncplc::plc
