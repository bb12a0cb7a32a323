// The Modbus address map of a project's tags (issue 5, first part): which
// coil, discrete input, input register or holding register shows which tag,
// by the convention HMI users know from OpenPLC:
//
//   %IXb.n  discrete input 8b+n   (0..8191)     %QXb.n  coil 8b+n              (0..8191)
//   %IWn    input register n      (0..1023)     %QWn    holding register n     (0..1023)
//   %MWn    holding 1024+n        (n 0..1023)   %MDn    holding 2048+2n, two   (n 0..1023)
//   %MLn    holding 4096+4n, four (n 0..1023)
//
// A tag's `modbus: {table, address}` (ModbusPlaces) places it explicitly,
// anywhere in the four tables, and takes precedence over the convention.
//
// An array tag occupies consecutive addresses. 32- and 64-bit values span two
// or four registers, high word first by default (WordOrder::HighFirst) or
// swapped (LowFirst); each register is big-endian on the wire, as Modbus
// defines. Addresses a tag does not cover are unmapped: the server answers
// exception 02 for them, never a plausible zero.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/modbus/modbus_config.hpp"
#include "runtime/modbus/register_codec.hpp"
#include "runtime/core/program.hpp"

namespace syncplc {

// One tag (or one element of an array tag) in one table.
struct ModbusPoint {
  std::uint32_t tag = 0;      // index in Program::tags
  std::uint32_t element = 0;  // 0-based element of the tag
  ModbusTable table = ModbusTable::HoldingRegisters;
  std::uint32_t address = 0;  // first coil/register
  std::uint32_t width = 1;    // coils: 1; registers: 1, 2 or 4
  bool writable = false;      // coils and holding registers of tags with hmi: readwrite
  // Where the server finds the value (copied from the tag, so a request never
  // looks the tag up): the owning task, the cell in its image, the type.
  std::uint16_t owner = 0;
  std::uint32_t cell = 0;
  IecType type = IecType::INT;
  // A status register (not a tag): of the task status block (`owner` is the
  // task) or of the store status block.
  enum class Status : std::uint8_t {
    None, State, AgeMs, Scans, PeriodUs,                                // task status
    StoreState, StoreSinceOk, StorePending, StoreDropped, StoreFailures  // store status
  } status = Status::None;
  bool explicit_place = false;  // placed by the tag's modbus: key, not by the convention
};

// The task status block: per task, from the first register + 8 × task index,
// input registers: +0 state (0 no scan yet, 1 running, 2 stopped: its values
// are stale, 3 late: no publication for three periods and a second, a scan
// that does not end), +1 age of its newest values in ms (saturating at
// 65535), +2..+5 its scans published (ULINT), +6..+7 its period in µs (UDINT).
inline constexpr std::uint32_t kTaskStatusRegisters = 8;
enum class TaskState : std::uint16_t { NotStarted = 0, Running = 1, Stopped = 2, Late = 3 };

// The store status block, from `server.store_status` (default 8990), input
// registers: +0 state (0 ok, 1 FAULT: the database refuses writes and
// records wait in a bounded queue, 2 off: no database), +1 seconds since the
// last commit (saturating; 65535 none yet), +2..+3 event records pending,
// +4..+5 records lost (event records, trend buckets), +6..+7 failed store runs (UDINTs).
inline constexpr std::uint32_t kStoreStatusRegisters = 8;
inline bool is_store_status(ModbusPoint::Status s) { return s >= ModbusPoint::Status::StoreState; }

// The coils or registers a tag takes, all elements together.
struct ModbusSpan {
  ModbusTable table = ModbusTable::HoldingRegisters;
  std::uint32_t first = 0;  // first coil/register
  std::uint32_t count = 0;  // coils/registers
  bool explicit_place = false;  // from the tag's modbus: key, not from the convention
};
// "holding registers 3000..3003", "coil 5".
std::string modbus_span_text(const ModbusSpan& s);

// Two tags that want the same coil or register. `tag` was left out of the
// map; `other` was placed before it (explicit places go first, then the
// convention's, each in declaration order).
struct ModbusOverlap {
  std::uint32_t tag = 0;    // index in the tags
  std::uint32_t other = 0;
  ModbusSpan span, other_span;
};

class ModbusMap {
 public:
  // Every tag with HMI access read or readwrite and a Modbus place: its
  // explicit one (`places`, by tag index), else the convention's for its
  // direct address; with the task status block at `server.task_status`.
  // A tag outside the convention's ranges, or an explicit place that does not
  // fit its table or type, is reported in `notes` (it stays reachable by its
  // name elsewhere, not by Modbus). A tag whose place overlaps one already
  // taken is left out and reported in `overlaps`, so the map stays free of
  // overlaps; the loader turns those into load errors.
  static ModbusMap build(const Program& p, const ModbusSettings& s, std::vector<std::string>* notes = nullptr,
                         std::vector<ModbusOverlap>* overlaps = nullptr);
  // The tags' points alone (no task status block).
  static ModbusMap build(const std::vector<Tag>& tags, const ModbusPlaces& places, std::vector<std::string>* notes = nullptr,
                         std::vector<ModbusOverlap>* overlaps = nullptr);

  // The point that starts exactly at `address`, or that covers it.
  const ModbusPoint* at(ModbusTable t, std::uint32_t address) const;
  // Every point of [address, address + count) in order, or nullopt when any
  // address in the range is unmapped or a multi-register value is cut by
  // the range's ends (Modbus exception 02).
  std::optional<std::vector<const ModbusPoint*>> range(ModbusTable t, std::uint32_t address, std::uint32_t count) const;
  // The same into `out` (cleared first; no allocation once it has grown): false when nullopt above.
  bool range(ModbusTable t, std::uint32_t address, std::uint32_t count, std::vector<const ModbusPoint*>& out) const;
  const std::vector<ModbusPoint>& points(ModbusTable t) const { return tables_[static_cast<int>(t)]; }

 private:
  std::array<std::vector<ModbusPoint>, 4> tables_;  // sorted by address
};

// The map as `syncplc check` prints it: one line a tag (arrays as a range),
// an explicit place marked "(explicit)".
void print_modbus_map(std::ostream& os, const Program& p, const ModbusMap& m, WordOrder order);

}  // namespace syncplc
