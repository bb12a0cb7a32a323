#include "runtime/store/trend_series.hpp"

#include <algorithm>

namespace syncplc::store {

std::vector<TrendSeries> trend_series(const Program& p, const StoreSettings& s) {
  std::vector<TrendSeries> out;
  for (const auto& spec : s.trends) {
    const Tag& tag = p.tags.at(spec.tag);
    const std::int64_t period = p.tasks.at(tag.owner)->config().period_ns;
    for (std::uint32_t k = 0; k < tag.length; ++k) {
      TrendSeries ts;
      ts.element = tag.is_array ? tag.array_lower + k : 0;
      ts.label = tag.is_array ? tag.name + "[" + std::to_string(ts.element) + "]" : tag.name;
      ts.tag = tag.name;
      ts.type = tag.type;
      ts.identity = tag_identity(tag);
      ts.unit = tag.unit;
      ts.task = tag.owner;
      ts.cell = tag.cell + k;
      // A bucket shorter than the task's period would hold at most one scan anyway.
      ts.rate_ns = std::max(spec.rate_ns, period);
      ts.deadband = spec.deadband;
      out.push_back(std::move(ts));
    }
  }
  return out;
}

void build_trend_folds(Program& p, const StoreSettings& s) {
  const auto series = trend_series(p, s);
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& ts = series[i];
    p.tasks[ts.task]->trends.add(static_cast<std::uint32_t>(i), ts.cell, ts.type, ts.rate_ns);
  }
  for (auto& t : p.tasks) t->trends.finalize();
}

}  // namespace syncplc::store
