#include "runtime/st/diagnostic.hpp"

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

namespace {

// Levenshtein distance, case-insensitive.
std::size_t edit_distance(std::string_view x, std::string_view y) {
  std::vector<std::size_t> d(y.size() + 1);
  for (std::size_t j = 0; j <= y.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= x.size(); ++i) {
    std::size_t diag = d[0];
    d[0] = i;
    for (std::size_t j = 1; j <= y.size(); ++j) {
      const std::size_t up = d[j];
      const bool same = std::toupper(static_cast<unsigned char>(x[i - 1])) ==
                        std::toupper(static_cast<unsigned char>(y[j - 1]));
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return d[y.size()];
}

}  // namespace

std::string closest_name(std::string_view name, const std::vector<std::string_view>& candidates) {
  // Names longer than any candidate cannot be close; bounds the work on hostile input.
  if (name.size() > 64) return "";
  std::string best;
  std::size_t best_d = name.size() / 3 + 1;
  for (std::string_view c : candidates)
    if (const std::size_t d = edit_distance(name, c); d < best_d && d > 0) {
      best = std::string(c);
      best_d = d;
    }
  return best;
}

}  // namespace syncplc::st
