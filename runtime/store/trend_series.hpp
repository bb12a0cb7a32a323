// The historian's series: one per element of each trended tag ("speed",
// "pos[1]", "pos[2]" ...), numbered in tag order. The loader gives each
// task's TrendFold its series (build_trend_folds), the historian stores them
// under their label: both number them with this one function.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/program.hpp"
#include "runtime/store/store_settings.hpp"

namespace syncplc::store {

struct TrendSeries {
  std::string label;        // the tag's name, with [i] for an array's element (its declared bounds)
  std::string tag;
  std::int64_t element = 0; // the declared index (0 for a scalar)
  IecType type = IecType::LREAL;
  std::string identity;     // its tag's (tag_identity, instance_signature.hpp): the variable, across loads
  std::string unit;
  std::uint16_t task = 0;
  std::uint32_t cell = 0;   // in the owner's image
  std::int64_t rate_ns = 0; // the bucket length: the trend's rate, at least the task's period
  double deadband = 0;
};

std::vector<TrendSeries> trend_series(const Program& p, const StoreSettings& s);

// Gives each task's TrendFold the series it owns and sizes its ring. The
// program must not run yet (the loader calls it).
void build_trend_folds(Program& p, const StoreSettings& s);

}  // namespace syncplc::store
