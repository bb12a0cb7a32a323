// Online change in `syncplc run`: the project file loaded again, checked,
// and switched in while every task goes on (runtime/core/program_change.hpp).
// Asked for by `syncplc reload` (control socket) or SIGHUP (a service).
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/program_change.hpp"
#include "runtime/core/realtime.hpp"
#include "runtime/cli/plc_store.hpp"
#include "runtime/cli/run_events.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc::cli {

struct ReloadResult {
  bool accepted = false;
  std::string summary;             // one line
  std::vector<std::string> lines;  // the errors (rejected) or the change report (accepted)
  std::vector<InstanceChange> instances;  // accepted: what became of each block instance
  std::string hash;                // accepted: the project store's content hash of the new program's files
};

// What a reload loads: the instance's project file (path ""), or another
// file, e.g. a stored version extracted for a rollback. origin and source
// go to the project store ("rollback", "version 3").
struct ReloadFrom {
  std::string path;
  std::string origin = "reload";
  std::string source;
};

class Reloader {
 public:
  Reloader(std::string project, LoadOptions options, std::optional<int> modbus_port)
      : project_(std::move(project)), options_(std::move(options)), modbus_port_(modbus_port) {}
  ~Reloader();

  // Loads the file again and, when it is good, switches the running program
  // to it. A project that fails to load, or whose new drivers do not open,
  // changes nothing. Old events are printed to `events` before the old
  // program goes.
  ReloadResult reload(std::unique_ptr<Program>& program, RealtimeRunner& runner,
                      std::unique_ptr<modbus::Server>& server, PlcStore* store, std::ostream& events,
                      const ReloadFrom& from = {});
  // Completes a change that waited for a late task, once it has switched.
  // `store`: told that the old program's tasks ended (PlcStore::tasks_ended).
  void poll(RealtimeRunner& runner, std::ostream& events, PlcStore* store = nullptr);
  bool change_pending() const { return pending_ != nullptr; }
  // The event log: the old program's last events, and the audit trail of a
  // Modbus server the change restarts.
  void set_event_log(RunEvents* log) { log_ = log; }
  // Other threads that use the running program (the HTTP API, web_host.hpp):
  // `hold` keeps them out from just before the change begins until
  // `switch_to` has told them the new program (as the Modbus server is held
  // and given it), so nothing they queue can land in an old task that no
  // longer takes its queue; from then on they never use the old program,
  // which goes later.
  void set_readers(std::function<std::unique_lock<std::mutex>()> hold, std::function<void(Program&)> switch_to) {
    hold_readers_ = std::move(hold);
    on_switch_ = std::move(switch_to);
  }
  // What a server started anew shows in its store status registers.
  void set_store_status(const modbus::StoreStatusSource* s) { store_status_ = s; }

 private:
  std::string project_;
  LoadOptions options_;
  std::optional<int> modbus_port_;
  RunEvents* log_ = nullptr;
  const modbus::StoreStatusSource* store_status_ = nullptr;
  std::function<std::unique_lock<std::mutex>()> hold_readers_;
  std::function<void(Program&)> on_switch_;
  // A change one task has not reached yet (a scan that does not end): the
  // old program stays until it does (poll), never destroyed under its thread.
  std::unique_ptr<ProgramChange> pending_;
  std::unique_ptr<Program> pending_old_;
  std::vector<std::pair<std::size_t, std::size_t>> pending_takeovers_;  // (old, new) driver bindings (IoDriver::take_over)
};

}  // namespace syncplc::cli
