// What the HTTP server needs of the running PLC, and nothing more: the
// server (runtime/web) knows the core's Program and the store's tables; the
// run command (runtime/cli/web_host.*) implements this with its main thread,
// which alone replaces the program (online change) and owns the reloader.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/project/loader.hpp"

namespace syncplc::web {

// An online change asked for over HTTP; carried out by `run`'s main thread
// exactly as `syncplc reload` is.
struct ChangeRequest {
  enum class Kind { Load, Reload, Rollback } kind = Kind::Reload;
  std::string project_file;  // Load: the uploaded project's main file, written under the state directory
  std::int64_t version = 0;  // Rollback: the project store's version
  std::string user, client;  // who asked, for the event log
};

struct ChangeOutcome {
  bool accepted = false;
  int status = 200;                // the HTTP status of a refusal: 400 (the project's errors), 409 (the PLC's state)
  std::string summary;             // one line
  std::vector<std::string> lines;  // the errors ("file:line:col: message") or the change report
  nlohmann::json report = nlohmann::json::object();  // accepted: {"kept", "retuned", "new", "removed"} instance names
};

class PlcHost {
 public:
  virtual ~PlcHost() = default;
  // Runs f with the running program; no online change replaces it meanwhile.
  // From HTTP threads only, never from a task thread; f must not call change().
  virtual void with_program(const std::function<void(Program&)>& f) = 0;
  // Changes with every switch of the running program (refs resolved once per generation).
  virtual std::uint64_t program_generation() const = 0;
  // The runtime part of GET /status: uptime_s, store, modbus, project_file ...
  // and "task_states": {task: {"state", "stop_reason"}} for tasks that are not running.
  virtual nlohmann::json runtime_status() = 0;
  // Blocks until the main thread has carried out (or refused) the change.
  virtual ChangeOutcome change(const ChangeRequest& r) = 0;
  // An event for the log (kind "hmi-write", "force", "login", ...), source "http".
  virtual void record_event(const std::string& kind, const std::string& task, const std::string& message,
                            const std::string& client) = 0;
  // The PLC's database (users, events, trends, projects); ":memory:" or "" when it keeps none.
  virtual std::string database_path() const = 0;
  // Where uploaded projects are written (a directory only this user may read).
  virtual std::string upload_dir() const = 0;
  // How `run` loads projects (its --set overrides), for POST /projects/check.
  virtual LoadOptions load_options() const = 0;
};

}  // namespace syncplc::web
