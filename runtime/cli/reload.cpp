#include "runtime/cli/reload.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <ostream>

#include "runtime/cli/project_versions.hpp"
#include "runtime/cli/serve_modbus.hpp"
#include "runtime/core/iec_type.hpp"
#include "runtime/core/program_change.hpp"
#include "runtime/project/online_change.hpp"
#include "runtime/project/report.hpp"

namespace syncplc::cli {
namespace {

void sleep_ms(int ms) {
  timespec ts{0, ms * 1'000'000L};
  nanosleep(&ts, nullptr);
}

// A driver the change replaces and one of the same type that replaces it:
// the new one may take over what the old one holds open (IoDriver::will_take_over).
std::vector<std::pair<std::size_t, std::size_t>> takeovers(const Program& old, const Program& next,
                                                           const ProgramChange& change) {
  std::vector<std::pair<std::size_t, std::size_t>> out;  // (old binding, new binding)
  for (std::size_t b : change.new_drivers)
    for (std::size_t a : change.old_drivers)
      if (old.drivers[a].type == next.drivers[b].type) out.emplace_back(a, b);
  return out;
}

// After the switch, before the old drivers close.
void hand_over(Program& old, Program& next, const std::vector<std::pair<std::size_t, std::size_t>>& pairs) {
  for (const auto& [a, b] : pairs) next.drivers[b].driver->take_over(*old.drivers[a].driver);
}

}  // namespace

Reloader::~Reloader() {
  // `run` destroys the reloader after every task thread has been joined (a
  // thread stuck in a scan ends the process before this): nothing runs in a
  // pending change's old program any more.
  if (pending_ && pending_old_) {
    hand_over(*pending_old_, *pending_->to, pending_takeovers_);
    for (std::size_t a : pending_->old_drivers) pending_old_->drivers[a].driver->close();
  }
}

void Reloader::poll(RealtimeRunner& runner, std::ostream& events, PlcStore* store) {
  if (!pending_ || !runner.change_complete()) return;
  runner.finish_change();
  drain_task_events(events, *pending_old_, log_);
  if (store) store->tasks_ended(*pending_old_);  // the historian's last buckets of the old tasks
  hand_over(*pending_old_, *pending_->to, pending_takeovers_);
  for (std::size_t a : pending_->old_drivers) pending_old_->drivers[a].driver->close();
  pending_.reset();
  pending_old_.reset();
}

ReloadResult Reloader::reload(std::unique_ptr<Program>& program, RealtimeRunner& runner,
                              std::unique_ptr<modbus::Server>& server, PlcStore* store, std::ostream& events,
                              const ReloadFrom& from) {
  ReloadResult r;
  const std::string& file = from.path.empty() ? project_ : from.path;
  const std::string what = from.source.empty() ? file : from.source + " (" + file + ")";
  poll(runner, events, store);
  if (pending_) {
    r.summary = "reload refused: the previous change still waits for a task that has not reached its switch";
    return r;
  }
  auto next = load_project(file, options_);
  // Every load goes to the project store, accepted or rejected with its errors.
  auto record = [&](bool accepted) {
    if (!store) return;
    auto load = project_load(next, file, from.origin, from.source);
    load.accepted = accepted;
    if (!accepted && next.ok()) load.errors = r.lines;
    store->record(std::move(load));
  };
  if (!next.ok()) {
    for (const auto& d : next.diagnostics.sorted()) r.lines.push_back(d.text());
    r.summary = fmt::format("reload of {} rejected ({} error{}); the running program continues unchanged", what,
                            r.lines.size(), r.lines.size() == 1 ? "" : "s");
    record(false);
    return r;
  }
  Program& old = *program;
  auto change = plan_change(old, *next.program);

  // A changed driver takes over its predecessor's open connections at the
  // switch rather than opening its own beside them (a device that takes one
  // connection would refuse it, and the old one would write on until the
  // switch); modbus_client.hpp.
  const auto pairs = takeovers(old, *next.program, *change);
  for (const auto& [a, b] : pairs) next.program->drivers[b].driver->will_take_over(*old.drivers[a].driver);
  // The new program's own drivers open before anything switches: one that
  // fails leaves everything as it was.
  for (std::size_t i = 0; i < change->new_drivers.size(); ++i) {
    auto& d = *next.program->drivers[change->new_drivers[i]].driver;
    std::string err;
    if (!d.open(&err)) {
      for (std::size_t j = 0; j < i; ++j) next.program->drivers[change->new_drivers[j]].driver->close();
      r.lines.push_back("driver " + d.name() + ": " + err);
      r.summary = "reload of " + what + " rejected (a driver did not open); the running program continues unchanged";
      record(false);
      return r;
    }
  }

  // Modbus: no request is taken between hold and replace. From the change
  // on, the old tasks apply the new program's queues and mirror their
  // publications into it, so the server serves the new program at once:
  // reads see the running values, writes take effect at the next scan, and
  // a write and read that waited is answered once its write is published.
  const ModbusConfig next_cfg = server_config(next.modbus.server, modbus_port_);
  const bool keep_server = server && same_server(server->config(), next_cfg);
  std::unique_lock<std::mutex> readers;
  if (hold_readers_) readers = hold_readers_();
  if (keep_server) server->hold();
  change->switch_ns = switch_instant(*change, runner.now_ns());
  runner.begin_change(*change);
  if (keep_server) {
    server->replace_program(*next.program, next.modbus.places);
  } else if (server || next_cfg.enabled) {
    server.reset();  // changed settings: a new server (its clients reconnect)
    server = start_modbus(*next.program, next.modbus, modbus_port_, log_, store_status_);
  }
  if (on_switch_) on_switch_(*next.program);
  if (readers.owns_lock()) readers.unlock();
  // The store's jobs read the new program's snapshots from now on (the old
  // tasks mirror theirs into it until they switch), before the old one goes.
  if (store) store->switch_program(*next.program, next);
  // Each task switches at its first release at or after T, which is up to a
  // period after it; a task later than that and a second is stuck in a scan.
  std::int64_t longest = 0;
  for (const auto& t : next.program->tasks) longest = std::max(longest, t->config().period_ns);
  const std::int64_t give_up = change->switch_ns + longest + 1'000'000'000;
  while (!runner.change_complete() && runner.now_ns() < give_up) sleep_ms(1);

  r.accepted = true;
  r.lines = change_report(*change);
  r.instances = change->instances;
  r.hash = store::make_content(next.sources).hash;
  // What the switch cost: how late each task's first new scan started (a
  // complete change has them all: a handover is finished after that scan).
  std::int64_t late = 0;
  std::string late_task;
  for (const auto& h : change->handovers) {
    const std::int64_t l = h->first_scan_late_ns.load(std::memory_order_relaxed);
    if (h->to && l > late) late = l, late_task = h->to->config().name;
  }
  r.lines.push_back(fmt::format("switch at {:.6f}s: the first scans of the new program started at most {}{} after their release",
                                static_cast<double>(change->switch_ns) * 1e-9, format_ns(late),
                                late_task.empty() ? "" : " (task " + late_task + ")"));
  r.summary = "reloaded " + what + ": " + change_summary(*change);
  record(true);
  if (!runner.change_complete()) {
    std::string stuck;
    for (const auto& h : change->handovers)
      if (!h->done.load() && h->from) stuck += (stuck.empty() ? "" : ", ") + h->from->config().name;
    r.summary += "; task " + stuck + " has not reached the switch yet (a scan that does not end?): the change completes when it does";
    // Its thread is still inside the old program: that stays until it switches.
    pending_ = std::move(change);
    pending_old_ = std::move(program);
    pending_takeovers_ = pairs;
    program = std::move(next.program);
    return r;
  }
  runner.finish_change();
  drain_task_events(events, old, log_);
  if (store) store->tasks_ended(old);  // the historian's last buckets of the old tasks
  hand_over(old, *next.program, pairs);
  for (std::size_t a : change->old_drivers) old.drivers[a].driver->close();
  change.reset();
  program = std::move(next.program);  // the old program (and the fresh blocks swapped into it) goes
  return r;
}

}  // namespace syncplc::cli
