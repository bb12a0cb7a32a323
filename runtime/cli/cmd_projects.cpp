// `syncplc projects [--db PATH]`: the versions in the project store, oldest
// first; `syncplc projects show N [--file F]`: a version's files as stored
// (so a user can diff two versions). Read through a read-only connection,
// also while the PLC runs (WAL).
#include <fmt/format.h>
#include <time.h>

#include <filesystem>
#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/store/database.hpp"
#include "runtime/store/project_store.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)

namespace {

// Wall time in UTC, to the second.
std::string utc_time(std::int64_t ns) {
  const time_t s = static_cast<time_t>(ns / 1'000'000'000);
  tm t{};
  gmtime_r(&s, &t);
  char buf[32];
  strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &t);
  return buf;
}

// The first error, shortened, and how many more.
std::string errors_summary(const std::vector<std::string>& errors) {
  if (errors.empty()) return "-";
  std::string first = errors.front();
  if (first.size() > 70) first = first.substr(0, 67) + "...";
  return errors.size() == 1 ? first : fmt::format("{} (+{} more)", first, errors.size() - 1);
}

void print_list(const std::vector<store::ProjectVersion>& versions) {
  std::cout << fmt::format("{:>4}  {:<19}  {:<8}  {:<8}  {:<24}  {:<8}  {:>5}  {}\n", "#", "time (UTC)", "origin",
                           "outcome", "project", "hash", "files", "errors");
  for (const auto& v : versions) {
    std::string project = v.project_name.empty() ? "-" : v.project_name + " " + v.project_version;
    std::cout << fmt::format("{:>4}  {:<19}  {:<8}  {:<8}  {:<24}  {:<8}  {:>5}  {}\n", v.number, utc_time(v.time_ns),
                             v.origin, v.accepted ? "accepted" : "rejected", project,
                             v.hash.empty() ? "-" : v.hash.substr(0, 8), v.files, errors_summary(v.errors));
  }
}

int show_version(SQLite::Database& db, std::int64_t number, const std::string& file) {
  auto v = store::find_version(db, number);
  if (!v) {
    std::cerr << "syncplc: projects: no version " << number << " (syncplc projects lists them)\n";
    return kExitInvalid;
  }
  const auto files = store::version_files(db, number);
  if (!file.empty()) {
    for (const auto& f : files)
      if (f.path == file) {
        std::cout << f.text;
        return kExitOk;
      }
    std::cerr << "syncplc: projects: version " << number << " has no file '" << file << "'; it has:";
    for (const auto& f : files) std::cerr << " " << f.path;
    std::cerr << "\n";
    return kExitInvalid;
  }
  std::cout << fmt::format("version {}: {} {} at {} UTC from {}, {}\n", v->number, v->origin,
                           v->project_name.empty() ? "(no project name)" : v->project_name + " " + v->project_version,
                           utc_time(v->time_ns), v->source, v->accepted ? "accepted" : "rejected");
  std::cout << "sha256 " << (v->hash.empty() ? "- (no file could be read)" : v->hash) << "\n";
  for (const auto& e : v->errors) std::cout << "error: " << e << "\n";
  for (const auto& f : files) {
    std::cout << "\n==> " << f.path << " <==\n" << f.text;
    if (!f.text.empty() && f.text.back() != '\n') std::cout << "\n";
  }
  return kExitOk;
}

}  // namespace

int cmd_projects(const std::string& db_option, std::int64_t show, const std::string& file) {
  const std::string path = db_option.empty() ? default_database_path() : db_option;
  if (path == store::kMemoryDatabase || !std::filesystem::exists(path)) {
    std::cerr << "syncplc: projects: no database at " << path << " (syncplc run makes it; --db names another)\n";
    return kExitInvalid;
  }
  std::string err;
  auto db = store::Database::open_read_only(path, &err);
  if (!db) {
    std::cerr << "syncplc: projects: " << err << "\n";
    return kExitInvalid;
  }
  if (show) return show_version(db->sql(), show, file);
  const auto versions = store::list_versions(db->sql());
  if (versions.empty()) {
    std::cout << "No project has been loaded onto the PLC of " << path << " yet.\n";
    return kExitOk;
  }
  print_list(versions);
  return kExitOk;
}

}  // namespace syncplc::cli
