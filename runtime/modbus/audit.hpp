// What the Modbus server tells the PLC's audit trail (docs/store.md, "The
// event log"): every write it acknowledges, with the client's address, and
// every connection it refuses. Called on the server thread; an
// implementation must not block it (the event log queues and counts drops).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "runtime/core/program.hpp"
#include "runtime/modbus/register_map.hpp"

namespace syncplc::modbus {

struct ClientAddress {
  std::uint32_t ip = 0;  // IPv4, host byte order
  std::uint16_t port = 0;
};
std::string client_text(ClientAddress c);  // "192.168.0.7:50211"

class ServerAudit {
 public:
  virtual ~ServerAudit() = default;
  // A write was queued (the client is told it succeeded): points[i] (a tag's
  // element in `program`) takes values[i], in address order.
  virtual void written(const Program& program, ClientAddress client, const ModbusPoint* const* points,
                       const QueuedWrite* values, std::size_t n) = 0;
  // A connection was closed at once: `why` says which limit refused it.
  virtual void refused(ClientAddress client, const char* why) = 0;
};

}  // namespace syncplc::modbus
