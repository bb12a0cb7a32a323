#include "runtime/st/diagnostic.hpp"

#include "runtime/core/closest_name.hpp"

#include <algorithm>
#include <cctype>

namespace syncplc::st {

bool StDiagnostics::has_errors() const { return error_count() > 0; }

std::size_t StDiagnostics::error_count() const {
  return static_cast<std::size_t>(std::count_if(list_.begin(), list_.end(), [](const StDiagnostic& d) {
    return d.severity == StDiagnostic::Severity::Error;
  }));
}

std::vector<StDiagnostic> StDiagnostics::sorted() const {
  std::vector<StDiagnostic> out = list_;
  std::stable_sort(out.begin(), out.end(), [](const StDiagnostic& a, const StDiagnostic& b) {
    return a.loc.line != b.loc.line ? a.loc.line < b.loc.line : a.loc.col < b.loc.col;
  });
  return out;
}

std::string closest_name(std::string_view name, const std::vector<std::string_view>& candidates) {
  return syncplc::closest_name(name, candidates);
}

}  // namespace syncplc::st
