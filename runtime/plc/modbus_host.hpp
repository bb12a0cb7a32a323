// Starting the Modbus TCP server of `syncplc run`, and telling whether a
// changed project can keep the running server (online change).
#pragma once

#include <memory>
#include <ostream>
#include <optional>

#include "runtime/core/program.hpp"
#include "runtime/modbus/server.hpp"

namespace syncplc::plc {

// The settings a running server cannot change without a restart.
bool same_server(const ModbusConfig& a, const ModbusConfig& b);
// The project's `modbus:` settings with `--modbus-port` applied.
ModbusConfig server_config(const ModbusConfig& project, std::optional<int> port_override);
// Starts the server of `p` when the settings enable it; prints where it
// listens, to `log`. nullptr when it is off or could not start (the reason
// is printed). `audit`: the event log's audit trail (writes, refused
// connections), or null. `store_status`: what the store status registers
// show, or null ("off").
std::unique_ptr<modbus::Server> start_modbus(Program& p, const ModbusSettings& s, std::optional<int> port_override,
                                             modbus::ServerAudit* audit, const modbus::StoreStatusSource* store_status,
                                             std::ostream& log);

}  // namespace syncplc::plc
