// The PLC's database (docs/store.md): one SQLite file per PLC instance, kept
// by the store thread only (the scan path never touches it). Opening it:
//
//   - resolves the path (symlinks, `..`) to the real file: the lock and the
//     files beside it (-wal, -shm, .lock, a moved-aside copy) are the real
//     file's, whatever name the caller gave;
//   - takes the instance lock (flock on `<real path>.lock`): a second
//     `syncplc run` on the same file gets a clear error, never a second writer;
//   - creates a missing file (and its directory);
//   - checks an existing one (`PRAGMA quick_check`) through a read-only
//     connection that never checkpoints. SQLite's result codes decide
//     (sqlite_result.hpp): a lock another connection holds (BUSY, LOCKED) is
//     waited for up to the busy timeout and then refused (report->busy),
//     nothing moved; a file that is not a database or is damaged (NOTADB,
//     CORRUPT, a failed quick_check) is moved aside to
//     `<real path>.corrupt-<time>` with its -wal and -shm byte for byte, and
//     a new one is created; any other error leaves the file alone;
//   - a write-protected file (no write permission bit, not writable by this
//     user, a read-only file system) is opened read-only when the caller
//     allows it (report->read_only), through a connection that creates no
//     -wal or -shm and changes no file's mode;
//   - sets WAL journaling and kStoreSynchronous (docs/store.md: what a power
//     cut can cost with it).
//
// Readers (`syncplc events`, `projects`, `trend`) open it read-only without
// the lock, also while the PLC runs: WAL lets them read beside the writer.
#pragma once

#include <SQLiteCpp/Database.h>

#include <memory>
#include <string>
#include <vector>

namespace syncplc::store {

// PRAGMA synchronous in WAL mode, chosen by measurement (docs/benchmarks.md,
// "Retain"): FULL syncs the WAL at each commit, so a commit the store thread
// reports has reached the disk, and a power cut loses nothing reported.
inline constexpr const char* kStoreSynchronous = "FULL";

// ":memory:": a database that lives as long as the process (nothing survives
// a restart; for tests and `--db :memory:`).
inline constexpr const char* kMemoryDatabase = ":memory:";

// How long a connection of the store waits for a lock another connection
// holds before SQLite answers BUSY (sqlite3_busy_timeout).
inline constexpr int kBusyTimeoutMs = 5000;

struct OpenOptions {
  int busy_timeout_ms = kBusyTimeoutMs;
  // A write-protected file is opened read-only (report->read_only) instead
  // of refused: `run` restores from it and records nothing.
  bool allow_read_only = false;
};

struct OpenReport {
  bool locked = false;      // another process holds the instance lock (open failed)
  bool busy = false;        // another connection held a lock on the file past the busy timeout (open failed, nothing moved)
  bool created = false;     // no file was there (or the bad one was moved aside)
  bool read_only = false;   // the file is write-protected: opened read-only (OpenOptions::allow_read_only)
  std::string read_only_reason;  // why: "its mode is 0444", "its file system is read-only"
  std::string moved_aside;  // where a corrupt or foreign file went; "" if none
  std::string problem;      // why it was moved aside ("file is not a database (SQLITE_NOTADB)", quick_check's first line)
};

class Database {
 public:
  // Opens `path` as the instance's writer (or reader, see report->read_only).
  // Null with `error` set when the lock is held by another process
  // (report->locked), another connection holds the file past the busy
  // timeout (report->busy), the file is write-protected and that is not
  // allowed, or it cannot be created or opened at all.
  static std::unique_ptr<Database> open(const std::string& path, OpenReport* report, std::string* error,
                                        const OpenOptions& options = {});
  // Opens an existing database to read (no lock, no checks, no creation).
  static std::unique_ptr<Database> open_read_only(const std::string& path, std::string* error);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  SQLite::Database& sql() { return *db_; }
  const std::string& path() const { return path_; }
  // The file itself, symlinks resolved.
  const std::string& real_path() const { return real_path_; }
  bool read_only() const { return read_only_; }

 private:
  Database() = default;
  std::string path_, real_path_;
  bool read_only_ = false;
  int lock_fd_ = -1;
  std::unique_ptr<SQLite::Database> db_;
  std::vector<std::string> remove_after_close_;  // files this connection made beside a read-only database
};

// The database file `path` names, symlinks (of the file and its
// directories) resolved, also for a file that does not exist yet.
std::string real_database_path(const std::string& path);
// The real file + ".lock": the file whose flock marks the writer.
std::string lock_file(const std::string& path);

}  // namespace syncplc::store
