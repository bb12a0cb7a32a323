// The PLC's side of the HTTP server (runtime/web/plc_host.hpp): the running
// program as readers see it (Plc::with_view: held against an online change
// replacing it, never taken by a scan), the runtime's status as the control
// thread last refreshed it, and online changes, carried out by the control
// thread as `syncplc reload` is.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <mutex>
#include <string>

#include "runtime/core/supervisor.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/plc/change_request.hpp"
#include "runtime/web/plc_host.hpp"

namespace syncplc::web {
class Server;
}

namespace syncplc::plc {

class Plc;
class StoreLink;

class WebHost final : public web::PlcHost {
 public:
  WebHost(Plc& plc, LoadOptions options, std::string upload_dir);

  // --- HTTP threads (web::PlcHost)
  void with_program(const std::function<void(Program&)>& f) override;
  std::uint64_t program_generation() const override;
  nlohmann::json runtime_status() override;
  web::ChangeOutcome change(const web::ChangeRequest& r) override;
  void record_event(const std::string& kind, const std::string& task, const std::string& message,
                    const std::string& client) override;
  std::string database_path() const override;
  std::string upload_dir() const override { return upload_dir_; }
  LoadOptions load_options() const override { return options_; }

  // --- the PLC
  // The status readers see (the control thread refreshes it).
  void set_status(nlohmann::json status);
  // The project store's hash of the running program's files (GET /projects' "running").
  void set_project_hash(std::string hash);
  // From now on every change is refused (the PLC is stopping).
  void close();

 private:
  Plc& plc_;
  LoadOptions options_;
  std::string upload_dir_;
  std::atomic<bool> closed_{false};
  std::mutex status_mutex_;
  nlohmann::json status_ = nlohmann::json::object();
  std::string project_hash_;
};

// A change's outcome as the HTTP API answers it.
web::ChangeOutcome change_outcome(const ChangeResult& r);

// What GET /status says of the runtime.
nlohmann::json runtime_status_json(const std::string& project, double uptime_s, const StoreLink& store,
                                   const modbus::Server* modbus, const web::Server* http, std::int64_t epoch_wall_ns,
                                   const Program& p, const Supervisor* supervisor);

}  // namespace syncplc::plc
