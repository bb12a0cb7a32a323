#include "runtime/plc/modbus_host.hpp"

#include <set>
#include <string>
#include <tuple>

namespace syncplc::plc {

bool same_server(const ModbusConfig& a, const ModbusConfig& b) {
  auto key = [](const ModbusConfig& c) {
    std::string nets;
    for (const auto& n : c.allowed_clients) nets += std::to_string(n.address) + "/" + std::to_string(n.prefix) + ",";
    return std::make_tuple(c.enabled, c.port, c.bind, c.unit_id, c.max_clients, c.idle_timeout_ns, c.word_order, nets,
                           c.read_only, c.cpus);
  };
  return key(a) == key(b);
}

ModbusConfig server_config(const ModbusConfig& project, std::optional<int> port_override) {
  ModbusConfig cfg = project;
  if (port_override) {
    cfg.enabled = true;
    cfg.port = *port_override;
  }
  return cfg;
}

std::unique_ptr<modbus::Server> start_modbus(Program& p, const ModbusSettings& s, std::optional<int> port_override,
                                             modbus::ServerAudit* audit, const modbus::StoreStatusSource* store_status,
                                             std::ostream& log) {
  ModbusConfig cfg = server_config(s.server, port_override);
  if (!cfg.enabled) return nullptr;
  auto server = std::make_unique<modbus::Server>(p, ModbusSettings{cfg, s.places});
  server->set_audit(audit);
  server->set_store_status(store_status);
  std::string err;
  if (!server->start(&err)) {
    log << "syncplc: modbus: " << err << "\n";
    return nullptr;
  }
  log << "syncplc: modbus: listening on " << server->endpoint() << " (unit " << cfg.unit_id << ", "
            << server->handler_map_size() << " values mapped)\n";
  if (server->off_task_cpus()) {
    std::set<int> pinned;
    for (const auto& t : p.tasks)
      if (t->config().cpu >= 0) pinned.insert(t->config().cpu);
    std::string cpus;
    for (int c : pinned) cpus += (cpus.empty() ? "" : ", ") + std::to_string(c);
    log << "syncplc: modbus: the server thread keeps off CPU " << cpus << " (pinned tasks)\n";
  }
  if (!server->warning().empty()) log << "syncplc: modbus: warning: " << server->warning() << "\n";
  return server;
}

}  // namespace syncplc::plc
