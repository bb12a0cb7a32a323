#include "runtime/plc/web_host.hpp"

#include "runtime/plc/plc.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/plc/store_status.hpp"
#include "runtime/store/database.hpp"
#include "runtime/web/server.hpp"

namespace syncplc::plc {

WebHost::WebHost(Plc& plc, LoadOptions options, std::string upload_dir)
    : plc_(plc), options_(std::move(options)), upload_dir_(std::move(upload_dir)) {}

void WebHost::with_program(const std::function<void(Program&)>& f) {
  plc_.with_view([&](const Plc::View& v) { f(v.program); });
}

std::uint64_t WebHost::program_generation() const { return plc_.generation_.load(std::memory_order_acquire); }

nlohmann::json WebHost::runtime_status() {
  std::lock_guard lock(status_mutex_);
  nlohmann::json j = status_;
  j["project_hash"] = project_hash_;
  return j;
}

void WebHost::set_project_hash(std::string hash) {
  std::lock_guard lock(status_mutex_);
  project_hash_ = std::move(hash);
}

void WebHost::set_status(nlohmann::json status) {
  std::lock_guard lock(status_mutex_);
  status_ = std::move(status);
}

web::ChangeOutcome WebHost::change(const web::ChangeRequest& r) {
  if (closed_.load()) {
    web::ChangeOutcome o;
    o.status = 409;
    o.summary = "the PLC is stopping: no online change now";
    return o;
  }
  ChangeRequest c;
  c.kind = r.kind == web::ChangeRequest::Kind::Load       ? ChangeRequest::Kind::Load
           : r.kind == web::ChangeRequest::Kind::Rollback ? ChangeRequest::Kind::Rollback
                                                          : ChangeRequest::Kind::Reload;
  c.path = r.kind == web::ChangeRequest::Kind::Load ? r.project_file : std::string();
  c.version = r.version;
  c.by = " by " + r.user + " from " + r.client;
  return change_outcome(plc_.change(std::move(c)));
}

void WebHost::close() { closed_.store(true); }

void WebHost::record_event(const std::string& kind, const std::string& task, const std::string& message,
                           const std::string& client) {
  plc_.store().record(store::EventRecord{store::wall_now_ns(), kind, task, std::nullopt, "http", message, client});
}

std::string WebHost::database_path() const { return plc_.store().on() ? plc_.store().path() : std::string(); }

web::ChangeOutcome change_outcome(const ChangeResult& rr) {
  web::ChangeOutcome o;
  o.accepted = rr.accepted;
  o.summary = rr.summary;
  o.lines = rr.lines;
  o.status = rr.status;
  nlohmann::json report{{"kept", nlohmann::json::array()},    {"retuned", nlohmann::json::array()},
                        {"rewired", nlohmann::json::array()}, {"new", nlohmann::json::array()},
                        {"removed", nlohmann::json::array()}};
  for (const auto& i : rr.instances) report[std::string(instance_fate_name(i.fate))].push_back(i.name);
  o.report = report;
  return o;
}

nlohmann::json runtime_status_json(const std::string& project, double uptime_s, const StoreLink& store,
                                   const modbus::Server* modbus, const web::Server* http, std::int64_t epoch_wall_ns,
                                   const Program& p, const Supervisor* supervisor) {
  const StoreStatus st = store_status(store);
  nlohmann::json states = nlohmann::json::object();
  for (std::size_t i = 0; i < p.tasks.size(); ++i) {
    const Task& t = *p.tasks[i];
    if (supervisor && supervisor->hung(&t))
      states[t.config().name] = {{"state", "hung"}, {"stop_reason", "a scan did not end: its outputs are safe, its thread given up"}};
    else if (t.stopped())
      states[t.config().name] = {{"state", "stopped"},
                                 {"stop_reason", t.stats.watchdog_trips.load() > 0 ? "its watchdog stopped it"
                                                                                   : "a driver's reaction stopped it"}};
  }
  return {{"version", "0.1.0"},
          {"project_file", project},
          {"uptime_s", uptime_s},
          {"epoch_wall_ns", epoch_wall_ns},
          {"store", {{"state", store_state_name(st.state)},
                     {"detail", st.error.empty() ? nlohmann::json(store.path()) : nlohmann::json(st.error)}}},
          {"modbus", modbus ? nlohmann::json(modbus->endpoint()) : nlohmann::json()},
          {"http", http ? nlohmann::json(http->url()) : nlohmann::json()},
          {"task_states", states}};
}

}  // namespace syncplc::plc
