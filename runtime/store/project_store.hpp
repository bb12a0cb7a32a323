// The project store (docs/store.md, "Projects"): every project loaded onto
// the PLC (`run`, `reload`, a rollback, a boot from the store, later an HTTP
// upload) is one version row with its time, origin and outcome (accepted, or
// rejected with its errors), referring to its content: all the files the
// loader read, the project file and its includes. Identical contents are
// stored once (keyed by their SHA-256).
//
// Names: each file's path relative to the deepest directory that holds them
// all (usually the project file's), so the layout, and so every include:,
// is the same when a version is extracted elsewhere.
//
// Content hash: SHA-256 over the project file first, then the other files in
// byte order of their names; for each: its name, a NUL byte, its size in
// decimal, a NUL byte, its bytes. Lower-case hex.
#pragma once

#include <SQLiteCpp/Database.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/store/source_file.hpp"

namespace syncplc::store {

// The files of one load, named and hashed as above; `files` in hash order
// (the project file first). Empty (hash "") when no file could be read.
struct ProjectContent {
  std::string hash;
  std::vector<SourceFile> files;  // path: the name within the version
};
ProjectContent make_content(const std::vector<SourceFile>& read);

// One load attempt, as recorded.
struct ProjectLoad {
  std::string origin;        // "run", "reload", "rollback", "boot", ...
  std::string source;        // where it came from: the project file's absolute path, "version 3"
  std::int64_t time_ns = 0;  // wall time (system clock), ns since the epoch
  bool accepted = false;
  std::string project_name, project_version;  // the project: section (accepted loads)
  std::vector<std::string> errors;            // the diagnostics (rejected loads), one per line
  ProjectContent content;
};

// One version row, as listed.
struct ProjectVersion {
  std::int64_t number = 0;
  std::int64_t time_ns = 0;
  std::string origin, source;
  bool accepted = false;
  std::string project_name, project_version;
  std::string hash;  // "" : no file could be read
  int files = 0;
  std::vector<std::string> errors;
};

// Creates or migrates the project store's tables (schema part "projects").
bool prepare_projects(SQLite::Database& db, std::string* error);
// Records a load in one transaction; returns its version number.
std::int64_t record_load(SQLite::Database& db, const ProjectLoad& load);
// Every version, oldest first.
std::vector<ProjectVersion> list_versions(SQLite::Database& db);
std::optional<ProjectVersion> find_version(SQLite::Database& db, std::int64_t number);
std::optional<ProjectVersion> last_accepted(SQLite::Database& db);
// A stored version's files (project file first); empty if it has none.
std::vector<SourceFile> version_files(SQLite::Database& db, std::int64_t number);

// For the retain part: does the project being started (its content hash,
// LoadResult::sources through make_content) equal the last accepted version
// in `db`? False when none was accepted yet. Ask before the projects job has
// recorded this start (its first run, on the store thread; every job's
// prepare() and switch_program() come before that).
bool same_as_last_accepted(SQLite::Database& db, const std::string& content_hash);

// Writes `files` under `dir` (made 0700, emptied first) and returns the
// project file's path; "" with `error` when it cannot. Names that would
// leave `dir` are refused.
std::string extract_files(const std::vector<SourceFile>& files, const std::string& dir, std::string* error);

}  // namespace syncplc::store
