// The store's state as `syncplc run` shows it (docs/store.md, "When the
// database refuses to write"): one line for the live screen, and the exit
// message. ok, FAULT (the database refuses writes: records wait in a bounded
// queue), off (no database could be opened) or read-only (the database is
// write-protected: values were restored from it, nothing is recorded).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "runtime/plc/store_link.hpp"
#include "runtime/modbus/store_status_source.hpp"

namespace syncplc::plc {

struct StoreStatus {
  enum class State : std::uint16_t { Ok = 0, Fault = 1, Off = 2, ReadOnly = 3 } state = State::Ok;
  std::string error;            // the last failure ("events: database or disk is full"), the reason it is off or read-only
  std::uint64_t pending = 0;    // event records waiting to be written
  std::uint64_t dropped = 0;    // event records lost to a full queue
  std::uint64_t trend_lost = 0;  // trend buckets lost to a full ring or queue (historian.hpp)
  std::uint64_t failures = 0;   // failed store runs since start
  std::int64_t since_ok_ns = -1;  // since the last successful commit; -1: none yet
};
StoreStatus store_status(const StoreLink& s);
// "ok", "FAULT", "off", "read-only": the state as /status and the HMI show it.
const char* store_state_name(StoreStatus::State s);

// The live screen's line (it cuts it at the screen's edge): "Store ok  plc.db",
// "Store FAULT  12 pending  3 failures  events: database or disk is full".
std::string store_status_line(const StoreStatus& st, const std::string& path);
// run's exit message: the state, what was not written and why; nothing
// when the store is ok and every event was recorded.
void print_store_status(std::ostream& os, const StoreLink& s);

// The store status block of input registers (docs/modbus.md, "Store status"),
// read by the Modbus server's thread.
modbus::StoreStatusWords store_status_words(const StoreStatus& st);
class StoreStatusRegisters final : public modbus::StoreStatusSource {
 public:
  explicit StoreStatusRegisters(const StoreLink& store) : store_(store) {}
  modbus::StoreStatusWords store_status_words() const override;

 private:
  const StoreLink& store_;
};

}  // namespace syncplc::plc
