// What the store status block of input registers shows (docs/modbus.md,
// "Store status"): the state of the PLC's database, read by the server thread
// from whoever owns the store (runtime/plc/store_status.hpp). The server has
// no idea what a store is; it asks this interface once per request that
// reads the block.
#pragma once

#include <cstdint>

namespace syncplc::modbus {

struct StoreStatusWords {
  std::uint16_t state = 2;            // 0 ok, 1 FAULT (writes refused, records queue), 2 off (no database)
  std::uint16_t since_ok_s = 0xFFFF;  // seconds since the last commit, saturating; 65535: none yet
  std::uint32_t pending = 0;          // event records waiting to be written
  std::uint32_t dropped = 0;          // records lost: event records (full queue) and trend buckets (full ring or queue)
  std::uint32_t failures = 0;         // failed store runs since start
};

class StoreStatusSource {
 public:
  virtual ~StoreStatusSource() = default;
  // Called on the server thread (never on a scan); may take the store's locks.
  virtual StoreStatusWords store_status_words() const = 0;
};

}  // namespace syncplc::modbus
