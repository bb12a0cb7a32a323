// The PLC's database (docs/store.md): one SQLite file per PLC instance, kept
// by the store thread only (the scan path never touches it). Opening it:
//
//   - takes the instance lock (flock on `<path>.lock`): a second `syncplc run`
//     on the same database gets a clear error, never a second writer;
//   - creates a missing file (and its directory);
//   - checks an existing one (`PRAGMA quick_check`); a file that is not a
//     database, or is damaged, is moved aside to `<path>.corrupt-<time>`
//     (with its -wal and -shm) and a new one is created: the PLC starts with
//     initial values and the report says so. The bad file is never written;
//   - sets WAL journaling and kStoreSynchronous (docs/store.md: what a power
//     cut can cost with it).
//
// Readers (`syncplc events`, `projects`, `trend`) open it read-only without
// the lock, also while the PLC runs: WAL lets them read beside the writer.
#pragma once

#include <SQLiteCpp/Database.h>

#include <memory>
#include <string>

namespace syncplc::store {

// PRAGMA synchronous in WAL mode, chosen by measurement (docs/benchmarks.md,
// "Retain"): FULL syncs the WAL at each commit, so a commit the store thread
// reports has reached the disk, and a power cut loses nothing reported.
inline constexpr const char* kStoreSynchronous = "FULL";

// ":memory:": a database that lives as long as the process (nothing survives
// a restart; for tests and `--db :memory:`).
inline constexpr const char* kMemoryDatabase = ":memory:";

struct OpenReport {
  bool locked = false;      // another process holds the instance lock (open failed)
  bool created = false;     // no file was there (or the bad one was moved aside)
  std::string moved_aside;  // where a corrupt or foreign file went; "" if none
  std::string problem;      // why it was moved aside ("file is not a database", quick_check's first line)
};

class Database {
 public:
  // Opens `path` as the instance's writer. Null with `error` set when the
  // lock is held by another process (report->locked), or the file cannot be
  // created or opened at all (a directory that cannot be written, ...).
  static std::unique_ptr<Database> open(const std::string& path, OpenReport* report, std::string* error);
  // Opens an existing database to read (no lock, no checks, no creation).
  static std::unique_ptr<Database> open_read_only(const std::string& path, std::string* error);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  SQLite::Database& sql() { return *db_; }
  const std::string& path() const { return path_; }

 private:
  Database() = default;
  std::string path_;
  int lock_fd_ = -1;
  std::unique_ptr<SQLite::Database> db_;
};

// `path` + ".lock": the file whose flock marks the writer.
std::string lock_file(const std::string& path);

}  // namespace syncplc::store
