#include "runtime/io/modbus_client/client_error.hpp"

namespace syncplc {
namespace {

struct Named {
  std::uint16_t code;
  std::string_view name;
};

// Slot order; slot 0 is None. Exception codes of the Modbus Application
// Protocol v1.1b3 §7; other exception codes share one slot.
constexpr Named kNames[] = {
    {0, "ok"},
    {1, "exception 01 illegal function"},
    {2, "exception 02 illegal data address"},
    {3, "exception 03 illegal data value"},
    {4, "exception 04 server device failure"},
    {5, "exception 05 acknowledge"},
    {6, "exception 06 server device busy"},
    {8, "exception 08 memory parity error"},
    {10, "exception 0A gateway path unavailable"},
    {11, "exception 0B gateway target failed to respond"},
    {255, "exception reply (other code)"},
    {256, "timeout"},
    {257, "connect failed"},
    {258, "connection lost"},
    {259, "not connected"},
    {260, "short reply"},
    {261, "oversized reply"},
    {262, "malformed reply"},
    {263, "wrong transaction id"},
    {264, "wrong unit id"},
    {265, "wrong function code"},
    {266, "wrong byte count"},
    {267, "write not echoed"},
    {268, "no reply yet"},
    {0xFFFF, "unknown error"},
};
static_assert(sizeof(kNames) / sizeof(kNames[0]) == kErrorSlots);

}  // namespace

std::size_t client_error_slot(std::uint16_t c) {
  for (std::size_t i = 0; i + 1 < sizeof(kNames) / sizeof(kNames[0]); ++i)
    if (kNames[i].code == c) return i;
  if (c >= 1 && c <= 255) return 10;  // another exception code
  return sizeof(kNames) / sizeof(kNames[0]) - 1;
}

std::string_view client_error_name(std::uint16_t c) { return kNames[client_error_slot(c)].name; }

std::uint16_t client_error_of_slot(std::size_t slot) {
  return slot < sizeof(kNames) / sizeof(kNames[0]) ? kNames[slot].code : 0xFFFF;
}

}  // namespace syncplc
