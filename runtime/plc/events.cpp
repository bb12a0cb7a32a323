#include "runtime/plc/events.hpp"

#include <fmt/format.h>

#include "runtime/core/iec_type.hpp"
#include "runtime/core/monotonic_clock.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::plc {

void EventRecorder::set_epoch(std::int64_t epoch_monotonic_ns) {
  wall_at_epoch_ns_ = store::wall_now_ns() - (monotonic_ns() - epoch_monotonic_ns);
}

void EventRecorder::started(const std::string& project, const std::string& database) {
  store_.record(store::EventRecord{store::wall_now_ns(), "start", "", std::nullopt, "run",
                                   "syncplc run " + project + " (database " + database + ")", ""});
}

void EventRecorder::stopped(const std::string& why) {
  store_.record(store::EventRecord{store::wall_now_ns(), "stop", "", std::nullopt, "run", why, ""});
}

void EventRecorder::start_failed(const std::string& why) {
  store_.record(store::EventRecord{store::wall_now_ns(), "start-failed", "", std::nullopt, "run", why, ""});
}

void EventRecorder::reloaded(bool accepted, const std::string& summary, const std::vector<std::string>& lines) {
  std::string message = summary;
  for (const auto& l : lines) message += "\n" + l;  // the errors of a rejected project, or what changed
  store_.record(store::EventRecord{store::wall_now_ns(), accepted ? "reload" : "reload-failed", "", std::nullopt,
                                   "run", message, ""});
}

void EventRecorder::task_event(const Program& p, const Event& e) {
  const auto& task = *p.tasks[e.task];
  std::string source = task.config().name;
  if (e.block >= 0 && static_cast<std::size_t>(e.block) < task.blocks.size())
    source += "/" + task.blocks[static_cast<std::size_t>(e.block)].name;
  record_task_event(task.config().name, source, e);
}

void EventRecorder::task_event(const std::string& task, const Event& e) { record_task_event(task, task, e); }

void EventRecorder::record_task_event(const std::string& task, const std::string& source, const Event& e) {
  std::string message = e.message + event_value_text(e);
  if (e.kind == EventKind::BlockFault) message += fmt::format(" (value {})", e.value);
  store_.record(store::EventRecord{
      wall_at_epoch_ns_ + e.time_ns, std::string(event_kind_name(e.kind)), task,
      e.scan == Event::kNoScan ? std::nullopt : std::optional<std::uint64_t>(e.scan), source, message, ""});
}

void EventRecorder::written(const Program& program, modbus::ClientAddress client, const ModbusPoint* const* points,
                        const QueuedWrite* values, std::size_t n) {
  // One event per request: the values in address order, as "tag[element] := value".
  std::string message;
  std::string task = n ? program.tasks[points[0]->owner]->config().name : "";
  for (std::size_t i = 0; i < n; ++i) {
    if (points[i]->owner != points[0]->owner) task.clear();  // a write to tags of two tasks
    const Tag& t = program.tags[points[i]->tag];
    if (!message.empty()) message += ", ";
    message += t.name;
    if (t.length > 1 || t.is_array) message += fmt::format("[{}]", t.array_lower + points[i]->element);
    message += " := " + format_value(t.type, values[i].value);
  }
  store_.record(store::EventRecord{store::wall_now_ns(), "hmi-write", task, std::nullopt, "modbus", message, modbus::client_text(client)});
}

void EventRecorder::refused(modbus::ClientAddress client, const char* why) {
  store_.record(store::EventRecord{store::wall_now_ns(), "modbus-refused", "", std::nullopt, "modbus",
                                   std::string("connection refused: ") + why, modbus::client_text(client)});
}

}  // namespace syncplc::plc
