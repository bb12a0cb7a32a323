#include "runtime/plc/project_versions.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "runtime/store/database.hpp"

namespace syncplc::plc {
namespace fs = std::filesystem;

store::ProjectLoad project_load(const LoadResult& r, const std::string& project_file, const std::string& origin,
                                const std::string& source) {
  store::ProjectLoad l;
  l.origin = origin;
  std::error_code ec;
  l.source = source.empty() ? fs::weakly_canonical(fs::absolute(project_file, ec), ec).string() : source;
  l.time_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  l.accepted = r.ok();
  if (r.program) {
    l.project_name = r.program->name;
    l.project_version = r.program->version;
  }
  for (const auto& d : r.diagnostics.sorted()) l.errors.push_back(d.text());
  l.content = store::make_content(r.sources);
  return l;
}

std::optional<ExtractedVersion> extract_version(const std::string& db_path, std::int64_t number, std::string* error,
                                                bool* no_such_version) {
  if (no_such_version) *no_such_version = false;
  if (db_path == store::kMemoryDatabase) {
    *error = "the database is in memory (--db :memory:): it keeps no project versions to load";
    return std::nullopt;
  }
  if (!fs::exists(db_path)) {
    *error = "no database at " + db_path + ", so no project to load from it" +
             (number ? "" : ": give a project file (syncplc run PROJECT)");
    return std::nullopt;
  }
  auto db = store::Database::open_read_only(db_path, error);
  if (!db) return std::nullopt;
  auto v = number ? store::find_version(db->sql(), number) : store::last_accepted(db->sql());
  if (!v) {
    if (no_such_version) *no_such_version = true;
    *error = number ? "there is no version " + std::to_string(number) + " in the database " + db_path + " (syncplc projects lists them)"
                    : "the database " + db_path + " holds no accepted project yet: give a project file (syncplc run PROJECT)";
    return std::nullopt;
  }
  if (!v->accepted) {
    *error = "version " + std::to_string(v->number) + " was rejected (" + std::to_string(v->errors.size()) +
             (v->errors.size() == 1 ? " error" : " errors") + "): only an accepted version can be loaded again";
    return std::nullopt;
  }
  // Content-addressed: written anew beside, then put in place. Beside the
  // database, as the uploads are: one place per database, and private (a
  // project may hold addresses and settings of the plant).
  const fs::path dir = fs::absolute(db_path).parent_path() / "projects";
  const std::string final_dir = (dir / v->hash).string(), tmp = final_dir + ".tmp-" + std::to_string(getpid());
  std::error_code ec;
  fs::create_directories(dir, ec);
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace, ec);
  std::string written = store::extract_files(store::version_files(db->sql(), v->number), tmp, error);
  if (written.empty()) return std::nullopt;
  fs::remove_all(final_dir, ec);
  fs::rename(tmp, final_dir, ec);
  if (ec) {
    *error = "cannot move " + tmp + " to " + final_dir + ": " + ec.message();
    return std::nullopt;
  }
  return ExtractedVersion{v->number, final_dir + written.substr(tmp.size())};
}

bool write_reload_request(const std::string& pid_file, std::int64_t version, std::string* error) {
  const std::string path = reload_request_file(pid_file), tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    f << "version " << version << "\n";
    if (!f.flush()) {
      *error = "cannot write " + tmp;
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *error = "cannot write " + path;
    return false;
  }
  return true;
}

std::int64_t take_reload_request(const std::string& pid_file) {
  const std::string path = reload_request_file(pid_file);
  std::ifstream f(path);
  std::string word;
  std::int64_t version = 0;
  if (f && f >> word >> version && word == "version" && version > 0) {
    std::remove(path.c_str());
    return version;
  }
  std::remove(path.c_str());
  return 0;
}

void record_rejected_run(const std::string& db_path, const store::ProjectLoad& load) {
  if (db_path == store::kMemoryDatabase) return;
  store::OpenReport report;
  std::string error;
  auto db = store::Database::open(db_path, &report, &error);
  if (!db) return;  // held by a running instance, or cannot be opened: the run's errors are printed anyway
  try {
    if (store::prepare_projects(db->sql(), &error)) store::record_load(db->sql(), load);
  } catch (const std::exception&) {
    // Not recorded; the run's errors are printed anyway.
  }
}

}  // namespace syncplc::plc
