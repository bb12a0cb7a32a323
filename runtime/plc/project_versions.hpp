// The project store seen from the command line (docs/store.md, "Projects"):
// a load recorded as a version, a stored version extracted to run it (a boot
// from the store, a rollback by online change), and the request file through
// which `syncplc reload --version N` asks a running instance for a rollback.
#pragma once

#include <optional>
#include <string>

#include "runtime/project/loader.hpp"
#include "runtime/store/project_store.hpp"

namespace syncplc::plc {

// A load as the project store records it: `origin` "run", "reload",
// "rollback", "boot"; `source` where it came from ("" : the project file's
// absolute path).
store::ProjectLoad project_load(const LoadResult& r, const std::string& project_file, const std::string& origin,
                                const std::string& source = "");

// A stored version written out to run: the project file's path.
struct ExtractedVersion {
  std::int64_t number = 0;
  std::string project_file;
};
// Version `number` (0: the last accepted one) of the database at `db_path`,
// read through its own read-only connection and written beside the
// database (DIR/projects/HASH for DIR/plc.db, each directory 0700, as the
// uploads beside it). Nullopt with `error` when there is none (then
// `no_such_version` is set), it was rejected, or it cannot be written.
std::optional<ExtractedVersion> extract_version(const std::string& db_path, std::int64_t number, std::string* error,
                                                bool* no_such_version = nullptr);

// `syncplc reload --version N` leaves this beside the instance's pid file
// before it signals; `run` takes it (reads and removes) at the signal.
inline std::string reload_request_file(const std::string& pid_file) { return pid_file + ".request"; }
bool write_reload_request(const std::string& pid_file, std::int64_t version, std::string* error);
// The version asked for (0: none, a plain reload of the project file).
std::int64_t take_reload_request(const std::string& pid_file);

// Records a `run` whose project did not load in the database at `db_path`
// (nothing when another instance holds it: that one's writer owns it).
void record_rejected_run(const std::string& db_path, const store::ProjectLoad& load);

}  // namespace syncplc::plc
