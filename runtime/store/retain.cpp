#include "runtime/store/retain.hpp"

#include <SQLiteCpp/Statement.h>
#include <SQLiteCpp/Transaction.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/store/schema.hpp"

namespace syncplc::store {
namespace {

// Lines listing values not restored, at most: a project of thousands of
// renamed variables must not bury the rest of the start-up output.
constexpr std::size_t kMaxNoticeLines = 20;

const SchemaPart kRetainSchema{
    "retain",
    {
        // One row per retained variable. value: its cells, 8 bytes each, as in
        // the process image (little-endian); shown: the same for a human
        // reading the table with the sqlite3 shell. The project row: the
        // content hash of the project last started (a changed one reinitialises
        // retain values, as a download does on CODESYS).
        "CREATE TABLE retain_value ("
        "  name TEXT PRIMARY KEY,"
        "  kind TEXT NOT NULL,"
        "  identity TEXT NOT NULL,"
        "  persistent INTEGER NOT NULL,"
        "  value BLOB NOT NULL,"
        "  shown TEXT NOT NULL,"
        "  stored_at INTEGER NOT NULL);"
        "CREATE TABLE retain_project ("
        "  id INTEGER PRIMARY KEY CHECK (id = 1),"
        "  content_hash TEXT NOT NULL,"
        "  file TEXT NOT NULL,"
        "  started_at INTEGER NOT NULL);",
    }};

std::int64_t unix_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// What a person reading the table sees: "42", "[1, 2, 3]", "CTU<INT> state".
std::string shown(const Program& p, const RetainVar& v, const Cell* cells) {
  if (v.instance >= 0) {
    std::string s;
    for (std::uint32_t k = 0; k < v.length; ++k) s += fmt::format("{}{:#x}", k ? " " : "", cells[k].raw);
    return s;
  }
  const Tag& t = p.tags[static_cast<std::size_t>(v.tag)];
  if (v.length == 1 && !t.is_array) return format_value(t.type, cells[0]);
  std::string s = "[";
  for (std::uint32_t k = 0; k < v.length; ++k) s += (k ? ", " : "") + format_value(t.type, cells[k]);
  return s + "]";
}

std::vector<std::uint8_t> to_blob(const Cell* cells, std::uint32_t n) {
  std::vector<std::uint8_t> b(n * sizeof(Cell));
  std::memcpy(b.data(), cells, b.size());
  return b;
}

void upsert(SQLite::Statement& q, const Program& p, const RetainVar& v, const Cell* cells, std::int64_t now) {
  const auto blob = to_blob(cells, v.length);
  q.reset();
  q.bind(1, v.name);
  q.bind(2, v.kind);
  q.bind(3, v.identity);
  q.bind(4, v.persistent ? 1 : 0);
  q.bind(5, blob.data(), static_cast<int>(blob.size()));
  q.bind(6, shown(p, v, cells));
  q.bind(7, static_cast<std::int64_t>(now));
  q.exec();
}

constexpr const char* kUpsert =
    "INSERT INTO retain_value (name, kind, identity, persistent, value, shown, stored_at) VALUES (?, ?, ?, ?, ?, ?, ?) "
    "ON CONFLICT (name) DO UPDATE SET kind = excluded.kind, identity = excluded.identity, "
    "persistent = excluded.persistent, value = excluded.value, shown = excluded.shown, stored_at = excluded.stored_at";

void record_project(SQLite::Database& db, const Program& p, const std::string& hash) {
  SQLite::Statement q(db,
                      "INSERT INTO retain_project (id, content_hash, file, started_at) VALUES (1, ?, ?, ?) "
                      "ON CONFLICT (id) DO UPDATE SET content_hash = excluded.content_hash, file = excluded.file, "
                      "started_at = excluded.started_at");
  q.bind(1, hash);
  q.bind(2, p.file);
  q.bind(3, static_cast<std::int64_t>(unix_ns()));
  q.exec();
}


}  // namespace

std::optional<StartMode> parse_start_mode(std::string_view text) {
  if (text == "warm") return StartMode::Warm;
  if (text == "cold") return StartMode::Cold;
  if (text == "origin") return StartMode::Origin;
  return std::nullopt;
}

std::string_view start_mode_name(StartMode m) {
  switch (m) {
    case StartMode::Warm: return "warm";
    case StartMode::Cold: return "cold";
    case StartMode::Origin: return "origin";
  }
  return "?";
}

std::vector<RetainVar> retained_vars(const Program& p) {
  std::vector<RetainVar> vars;
  for (std::size_t i = 0; i < p.tags.size(); ++i) {
    const Tag& t = p.tags[i];
    if (t.retain || t.persistent)
      vars.push_back({t.name, "tag", tag_identity(t), t.persistent, t.owner, t.cell, t.length, -1, static_cast<int>(i)});
  }
  for (std::size_t i = 0; i < p.retained.size(); ++i) {
    const auto& r = p.retained[i];
    vars.push_back({r.name, "block", r.identity, r.persistent,
                    r.task, r.cell, r.length, static_cast<int>(i), -1});
  }
  return vars;
}

bool prepare_retain_tables(SQLite::Database& db, std::string* error) { return ensure_schema(db, kRetainSchema, error); }

bool retain_tables_readable(SQLite::Database& db, std::string* error) {
  const int have = schema_version(db, kRetainSchema.name);
  const int known = static_cast<int>(kRetainSchema.migrations.size());
  if (have == 0 || have == known) return true;
  *error = "the database's retain tables are version " + std::to_string(have) + " and this syncplc reads version " +
           std::to_string(known) + (have < known ? " (a read-only database is not migrated)" : "");
  return false;
}

// The restore's access to the images (image_access.hpp): before the first
// scan, no thread runs the program.
class RetainRestore {
 public:
  static std::vector<std::string> restore(SQLite::Database& db, Program& p, StartMode mode, const std::string& hash,
                                          bool record);
  static void read(const Program& p, const RetainVar& v, Cell* out) {
    const Cell* c = p.tasks[v.task]->image(ImageAccess{}).data() + v.cell;
    std::copy(c, c + v.length, out);
  }

 private:
  static Cell* image_of(Program& p, const RetainVar& v) { return p.tasks[v.task]->image(ImageAccess{}).data() + v.cell; }
};

std::vector<std::string> restore_retain(SQLite::Database& db, Program& p, StartMode mode, const std::string& hash,
                                        bool record) {
  return RetainRestore::restore(db, p, mode, hash, record);
}

std::vector<std::string> RetainRestore::restore(SQLite::Database& db, Program& p, StartMode mode,
                                                const std::string& hash, bool record) {
  std::vector<std::string> lines, missed;
  const auto vars = retained_vars(p);
  const bool tables = db.tableExists("retain_value");  // a read-only database may have none yet
  std::string last_hash;
  if (tables) {
    SQLite::Statement q(db, "SELECT content_hash FROM retain_project WHERE id = 1");
    if (q.executeStep()) last_hash = q.getColumn(0).getString();
  }
  const bool changed = !last_hash.empty() && last_hash != hash;
  struct Stored {
    std::string identity;
    std::vector<Cell> cells;
  };
  std::map<std::string, Stored> stored;
  if (tables && mode != StartMode::Origin) {
    SQLite::Statement q(db, "SELECT name, identity, value FROM retain_value");
    while (q.executeStep()) {
      Stored s{q.getColumn(1).getString(), {}};
      const auto blob = q.getColumn(2);
      s.cells.resize(static_cast<std::size_t>(blob.getBytes()) / sizeof(Cell));
      std::memcpy(static_cast<void*>(s.cells.data()), blob.getBlob(), s.cells.size() * sizeof(Cell));
      stored.emplace(q.getColumn(0).getString(), std::move(s));
    }
  }

  std::size_t restored = 0;
  std::set<std::string> declared;
  std::vector<const RetainVar*> initial;  // not restored: the row is to hold the initial value
  for (const auto& v : vars) {
    declared.insert(v.name);
    auto it = stored.find(v.name);
    std::string why;
    if (it == stored.end()) why = "";  // new: nothing to restore, not worth a line
    else if (it->second.identity != v.identity) why = "stored as " + it->second.identity + ", now " + v.identity;
    else if (it->second.cells.size() != v.length) why = "stored value has the wrong size";
    else if (!v.persistent && mode == StartMode::Cold) why = "cold start (only persistent values are kept)";
    else if (!v.persistent && changed) why = "the project changed since the last start (declare it persistent: to keep it)";
    if (it != stored.end() && why.empty()) {
      Cell* dst = image_of(p, v);
      std::copy(it->second.cells.begin(), it->second.cells.end(), dst);
      if (v.instance >= 0) {
        const auto& r = p.retained[static_cast<std::size_t>(v.instance)];
        p.tasks[r.task]->blocks[r.position].block->load_retain(dst);
      }
      ++restored;
      continue;
    }
    if (!why.empty()) missed.push_back(v.name + ": not restored: " + why);
    initial.push_back(&v);
  }
  std::size_t dropped = 0;
  for (const auto& [name, s] : stored)
    if (!declared.count(name)) ++dropped;

  if (record) {
    SQLite::Transaction tr(db);
    // The rows now hold what the PLC starts with: a crash before the first
    // store cycle must not bring back the value just refused.
    SQLite::Statement up(db, kUpsert);
    const std::int64_t now = unix_ns();
    for (const RetainVar* v : initial) upsert(up, p, *v, image_of(p, *v), now);
    if (dropped || mode == StartMode::Origin) {
      // Values of variables the project no longer retains go (CODESYS drops them too).
      SQLite::Statement all(db, "SELECT name FROM retain_value");
      std::vector<std::string> gone;
      while (all.executeStep())
        if (!declared.count(all.getColumn(0).getString())) gone.push_back(all.getColumn(0).getString());
      SQLite::Statement del(db, "DELETE FROM retain_value WHERE name = ?");
      for (const auto& g : gone) {
        del.reset();
        del.bind(1, g);
        del.exec();
      }
    }
    record_project(db, p, hash);
    tr.commit();
  }

  // The channels start with the restored values: readers see them before the first scan.
  for (auto& t : p.tasks)
    for (auto& ch : t->channels) ch->fill(t->image(ImageAccess{}).data());

  if (vars.empty() && !dropped && mode != StartMode::Origin) return lines;  // nothing retained, nothing to say
  std::string head = fmt::format("retain: {} start: {} of {} retained values restored", start_mode_name(mode), restored,
                                 vars.size());
  if (mode == StartMode::Origin)
    head += record ? " (reset origin: every stored value deleted)" : " (reset origin: the read-only database keeps its values)";
  else if (changed) head += " (the project changed since the last start: retain values reinitialised, persistent kept)";
  if (dropped)
    head += fmt::format("; {} stored values of variables no longer retained {}", dropped,
                        record ? "dropped" : "left in the read-only database");
  lines.push_back(head);
  for (std::size_t i = 0; i < missed.size() && i < kMaxNoticeLines; ++i) lines.push_back("retain: " + missed[i]);
  if (missed.size() > kMaxNoticeLines) lines.push_back(fmt::format("retain: ... and {} more not restored", missed.size() - kMaxNoticeLines));
  return lines;
}

int reset_retain(SQLite::Database& db, StartMode mode) {
  SQLite::Transaction tr(db);
  int n = 0;
  if (mode == StartMode::Origin) {
    n = db.exec("DELETE FROM retain_value");
    db.exec("DELETE FROM retain_project");
  } else if (mode == StartMode::Cold) {
    n = db.exec("DELETE FROM retain_value WHERE persistent = 0");
  }
  tr.commit();
  return n;
}

RetainJob::RetainJob(Program& p, const StoreSettings& s, StartMode mode)
    : program_(&p), mode_(mode), interval_ns_(s.retain_interval_ns) {
  switch_program(p, s);
  pending_hash_.clear();  // the start records its content in prepare()
}

bool RetainJob::prepare(Database& db, std::string* error) {
  if (!prepare_retain_tables(db.sql(), error)) return false;
  notices_ = restore_retain(db.sql(), *program_, mode_, content_hash_);
  // The restored values are what is stored now.
  for (std::size_t i = 0; i < vars_.size(); ++i) {
    RetainRestore::read(*program_, vars_[i], &stored_[offset_[i]]);
    known_[i] = true;
  }
  schedule(monotonic_ns() + interval_ns_);
  return true;
}

void RetainJob::schedule(std::int64_t next_ns) {
  next_ns_ = next_ns;
  due_.store(vars_.empty() ? INT64_MAX : next_ns, std::memory_order_relaxed);
}

void RetainJob::switch_program(Program& next, const StoreSettings& settings) {
  // Values already committed stay known by identity: an online change that
  // keeps a variable does not rewrite it.
  std::map<std::string, std::pair<std::string, std::vector<Cell>>> before;
  for (std::size_t i = 0; i < vars_.size(); ++i)
    if (known_[i])
      before[vars_[i].name] = {vars_[i].identity, {stored_.begin() + offset_[i], stored_.begin() + offset_[i] + vars_[i].length}};
  program_ = &next;
  interval_ns_ = settings.retain_interval_ns;
  vars_ = retained_vars(next);
  offset_.clear();
  std::uint32_t n = 0;
  for (const auto& v : vars_) {
    offset_.push_back(n);
    n += v.length;
  }
  taken_.assign(n, Cell{});
  stored_.assign(n, Cell{});
  known_.assign(vars_.size(), false);
  for (std::size_t i = 0; i < vars_.size(); ++i) {
    auto it = before.find(vars_[i].name);
    if (it != before.end() && it->second.first == vars_[i].identity && it->second.second.size() == vars_[i].length) {
      std::copy(it->second.second.begin(), it->second.second.end(), stored_.begin() + offset_[i]);
      known_[i] = true;
    }
  }
  content_hash_ = settings.content_hash;
  pending_hash_ = content_hash_;
  schedule(next_ns_);
}

void RetainJob::take_values() {
  // One snapshot per task: the values of one task are never torn between scans.
  for (auto& task : program_->tasks) {
    const std::uint16_t t = task->index();
    task->with_published([&](const Cell* owned) {
      for (std::size_t i = 0; i < vars_.size(); ++i)
        if (vars_[i].task == t) std::copy(owned + vars_[i].cell, owned + vars_[i].cell + vars_[i].length, taken_.begin() + offset_[i]);
    });
  }
}

void RetainJob::run(Database& db, std::int64_t now_ns, bool final) {
  (void)final;  // the final run is a run like the others: the last snapshots
  schedule(now_ns + interval_ns_);
  take_values();
  std::vector<std::size_t> changed;
  for (std::size_t i = 0; i < vars_.size(); ++i)
    if (!known_[i] || !std::equal(taken_.begin() + offset_[i], taken_.begin() + offset_[i] + vars_[i].length,
                                  stored_.begin() + offset_[i], [](Cell a, Cell b) { return a.raw == b.raw; }))
      changed.push_back(i);
  last_written_ = 0;
  if (changed.empty() && pending_hash_.empty()) return;
  SQLite::Transaction tr(db.sql());
  SQLite::Statement up(db.sql(), kUpsert);
  const std::int64_t now = unix_ns();
  for (auto i : changed) upsert(up, *program_, vars_[i], taken_.data() + offset_[i], now);
  if (!pending_hash_.empty()) record_project(db.sql(), *program_, pending_hash_);
  tr.commit();
  // Only what was committed counts as stored (a failed run is retried whole).
  for (auto i : changed) {
    std::copy(taken_.begin() + offset_[i], taken_.begin() + offset_[i] + vars_[i].length, stored_.begin() + offset_[i]);
    known_[i] = true;
  }
  pending_hash_.clear();
  last_written_ = changed.size();
}

}  // namespace syncplc::store
