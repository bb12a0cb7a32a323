// Retain and persistent variables (docs/store.md, "Retain and persistent
// variables"): tags declared `retain:` or `persistent:` and block instances
// declared so (their state, Block::save_retain) are kept in the table
// retain_value, one row per variable, and put back before the first scan.
//
// A value is matched by the variable's identity, never by a hash of the
// program: its name, and its type (for a block instance: block type, datatype
// and state layout). CODESYS's starts:
//   warm   (default)  retain and persistent values come back; but when the
//                     project's content changed since the last start (a
//                     download, on CODESYS), retain values start from their
//                     initial values and only persistent ones come back;
//   cold              only persistent values come back;
//   origin            nothing comes back; every stored value is deleted.
#pragma once

#include <SQLiteCpp/Database.h>

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/store/store_thread.hpp"

namespace syncplc::store {

enum class StartMode { Warm, Cold, Origin };
std::optional<StartMode> parse_start_mode(std::string_view text);
std::string_view start_mode_name(StartMode m);

// One retained variable of a program: a tag, or a block instance's state.
struct RetainVar {
  std::string name;      // the tag's or the instance's name
  std::string kind;      // "tag" or "block"
  std::string identity;  // what must match to restore: "DINT", "ARRAY[1..4] OF LREAL", "CTU<INT> state 1 (2 cells)"
  bool persistent = false;
  std::uint16_t task = 0;
  std::uint32_t cell = 0;  // in the task's published range
  std::uint32_t length = 0;
  int instance = -1;  // index in Program::retained, -1 for a tag
  int tag = -1;       // index in Program::tags, -1 for an instance
};
std::vector<RetainVar> retained_vars(const Program& p);

// The retain part's tables (schema.hpp).
bool prepare_retain_tables(SQLite::Database& db, std::string* error);

// Whether the retain tables of a database that is only read (a read-only
// store) are ones this syncplc reads: none yet, or its own version (a read-only
// database cannot be migrated). False with `error` otherwise.
bool retain_tables_readable(SQLite::Database& db, std::string* error);

// Before the first scan: the stored values that may come back by `mode` into
// the program's images (and block states). With `record`, the database then
// holds exactly the values the PLC starts with, and `hash` as the last
// started content; without (a read-only store), it is only read.
// Returns the start-up notice lines (one summary, one per value not restored).
std::vector<std::string> restore_retain(SQLite::Database& db, Program& p, StartMode mode, const std::string& hash,
                                        bool record = true);

// `syncplc reset cold|origin`: cold deletes retain values (persistent ones
// stay), origin deletes every stored value. Returns how many were deleted.
int reset_retain(SQLite::Database& db, StartMode mode);

// The store thread's job: every retain_interval, and once more at a clean
// stop, takes the retained values from the published snapshots and writes
// the ones that changed, in one transaction.
class RetainJob final : public StoreJob {
 public:
  RetainJob(Program& p, const StoreSettings& s, StartMode mode);
  const char* name() const override { return "retain"; }
  bool prepare(Database& db, std::string* error) override;
  // The store thread asks this outside exclusive(), also while an online
  // change runs switch_program: hence an atomic, not vars_ and next_ns_.
  std::int64_t due_ns() const override { return due_.load(std::memory_order_relaxed); }
  void run(Database& db, std::int64_t now_ns, bool final) override;
  void switch_program(Program& next, const StoreSettings& settings) override;

  // The start-up notices of prepare() (restore_retain's lines).
  const std::vector<std::string>& start_notices() const { return notices_; }
  // Rows written by the last run (for tests and the benchmark).
  std::size_t last_written() const { return last_written_; }

 private:
  void take_values();
  void schedule(std::int64_t next_ns);

  Program* program_;
  StartMode mode_;
  std::int64_t interval_ns_;
  std::int64_t next_ns_ = 0;
  std::atomic<std::int64_t> due_{INT64_MAX};  // next_ns_, or INT64_MAX with nothing retained
  std::vector<RetainVar> vars_;
  std::vector<std::uint32_t> offset_;  // per var: its first cell in taken_ / stored_
  std::vector<Cell> taken_;            // from the snapshots, this run
  std::vector<Cell> stored_;           // as last committed
  std::vector<bool> known_;            // per var: stored_ holds its committed value
  std::string content_hash_;           // StoreSettings::content_hash of the program served
  std::string pending_hash_;           // an online change's content, recorded at the next run
  std::vector<std::string> notices_;
  std::size_t last_written_ = 0;
};

}  // namespace syncplc::store
