// "Did you mean …?": the suggestion for a misspelt name, one rule for every
// place that names one (block types in `syncplc blocks`, keywords and names
// in Structured Text). Header-only, so that libraries which take only the
// core's headers (the ST front end, its fuzzer) use it too.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cctype>
#include <string>
#include <string_view>
#include <vector>

namespace syncplc {

// Levenshtein distance, case-insensitive (IEC names are), or `limit` when
// it is `limit` or more: a distance is never below the difference of the
// lengths, and a row whose least value reaches the limit cannot come back
// under it, so both stop early. Names of up to 127 characters need no heap.
inline std::size_t name_distance(std::string_view x, std::string_view y, std::size_t limit = SIZE_MAX) {
  const std::size_t apart = x.size() > y.size() ? x.size() - y.size() : y.size() - x.size();
  if (apart >= limit) return limit;
  std::array<std::size_t, 128> row_small;
  std::vector<std::size_t> row_big;
  std::size_t* d = row_small.data();
  if (y.size() >= row_small.size()) {
    row_big.resize(y.size() + 1);
    d = row_big.data();
  }
  for (std::size_t j = 0; j <= y.size(); ++j) d[j] = j;
  for (std::size_t i = 1; i <= x.size(); ++i) {
    const int xi = std::toupper(static_cast<unsigned char>(x[i - 1]));
    std::size_t diag = d[0];
    d[0] = i;
    std::size_t least = d[0];
    for (std::size_t j = 1; j <= y.size(); ++j) {
      const std::size_t up = d[j];
      const bool same = xi == std::toupper(static_cast<unsigned char>(y[j - 1]));
      d[j] = std::min({d[j] + 1, d[j - 1] + 1, diag + (same ? 0 : 1)});
      least = std::min(least, d[j]);
      diag = up;
    }
    if (least >= limit) return limit;
  }
  return std::min(d[y.size()], limit);
}

// The candidate closest to `name`, at most a third of its letters wrong (a
// candidate that differs only in case is closest of all), or "" when none is
// close. Names over 64 characters get no suggestion: no candidate is that
// long, and it bounds the work on hostile input.
template <class Names>
std::string closest_name(std::string_view name, const Names& candidates) {
  if (name.size() > 64) return "";
  std::string_view best;
  std::size_t best_d = name.size() / 3 + 1;
  for (const auto& c : candidates) {
    const std::string_view cv(c);
    if (const std::size_t d = name_distance(name, cv, best_d); d < best_d) {
      best = cv;
      best_d = d;
    }
  }
  return std::string(best);
}

}  // namespace syncplc
