// `syncplc reset cold|origin`: CODESYS's reset cold and reset origin for the
// stored retain values, done while the PLC is stopped (the instance lock
// refuses it while a `syncplc run` holds the database). The next start then
// brings back only what is left: nothing of a retain variable after cold,
// nothing at all after origin.
#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/plc/store_link.hpp"
#include "runtime/store/retain.hpp"

namespace syncplc::cli {
using namespace plc;  // the PLC instance's database paths and stored versions (runtime/plc)


int cmd_reset(const std::string& kind, const std::string& project, const std::string& db) {
  store::StoreSettings settings;
  if (!project.empty() && db.empty()) {
    auto r = load_or_report(project, LoadOptions{});
    if (!r.ok()) return kExitInvalid;
    settings = r.store;
  }
  const std::string path = database_path(db, settings, project);
  store::OpenReport report;
  std::string err;
  auto database = store::Database::open(path, &report, &err);
  if (!database) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  if (!report.moved_aside.empty())
    std::cerr << "syncplc: warning: the database " << path << " was unreadable (" << report.problem << "); it was moved to "
              << report.moved_aside << "\n";
  if (!store::prepare_retain_tables(database->sql(), &err)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  const auto mode = *store::parse_start_mode(kind);
  const int n = store::reset_retain(database->sql(), mode);
  std::cout << "reset " << kind << ": " << n << " stored value" << (n == 1 ? "" : "s") << " deleted from " << path
            << (mode == store::StartMode::Cold ? " (persistent values kept)" : "") << "\n";
  return kExitOk;
}

}  // namespace syncplc::cli
