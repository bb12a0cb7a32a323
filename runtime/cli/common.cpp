#include <iostream>

#include "runtime/cli/commands.hpp"

namespace syncplc::cli {

LoadResult load_or_report(const std::string& path, const LoadOptions& options) {
  LoadResult r = load_project(path, options);
  if (!r.ok()) {
    for (const auto& d : r.diagnostics.sorted()) std::cerr << d.text() << "\n";
    std::cerr << path << ": " << r.diagnostics.size() << (r.diagnostics.size() == 1 ? " error" : " errors")
              << ", project not loaded\n";
  }
  return r;
}

bool parse_sets(const std::vector<std::string>& sets, LoadOptions& options) {
  for (const auto& s : sets) {
    ParamOverride o;
    if (!parse_override(s, o)) {
      std::cerr << "syncplc: --set " << s << ": write instance.param=value (or tag=value)\n";
      return false;
    }
    options.overrides.push_back(o);
  }
  return true;
}

}  // namespace syncplc::cli
