#include "runtime/modbus/audit.hpp"

#include <fmt/format.h>

namespace syncplc::modbus {

std::string client_text(ClientAddress c) {
  return fmt::format("{}.{}.{}.{}:{}", c.ip >> 24, (c.ip >> 16) & 0xFF, (c.ip >> 8) & 0xFF, c.ip & 0xFF, c.port);
}

}  // namespace syncplc::modbus
