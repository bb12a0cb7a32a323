#include "runtime/web/value_quality.hpp"

#include <algorithm>

#include "runtime/core/reference.hpp"

namespace syncplc::web {

const char* quality_name(Quality q) {
  switch (q) {
    case Quality::Good: return "good";
    case Quality::Forced: return "forced";
    case Quality::DriverNotOk: return "driver_not_ok";
    case Quality::Stale: return "stale";
    case Quality::TaskStopped: return "task_stopped";
  }
  return "stale";
}

ValueQuality judge_value(const QualityInputs& in) {
  ValueQuality out;
  // `now` is read before the value, so a reader delayed between the two
  // (an HTTP worker at nice 10) never makes a value look older than it is.
  if (in.now_ns >= 0 && in.stamp.scan > 0) out.age_ns = std::max<std::int64_t>(0, in.now_ns - in.stamp.release_ns);
  if (in.task_stopped) out.quality = Quality::TaskStopped;
  else if (in.stamp.scan == 0 || (in.now_ns >= 0 && out.age_ns > stale_after_ns(in.period_ns))) out.quality = Quality::Stale;
  else if (!in.driver_ok) out.quality = Quality::DriverNotOk;
  else if (in.forced) out.quality = Quality::Forced;
  return out;
}

std::optional<ValueSource> value_source(const Program& p, const std::string& ref, std::string* why) {
  const auto cell = p.resolve(ref, why);
  if (!cell) return std::nullopt;
  ValueSource s;
  s.cell = *cell;
  s.task = p.tasks[cell->task].get();
  const auto parsed = parse_reference(ref, nullptr);
  if (!parsed || parsed->dotted()) return s;  // a pin: its block's output, no driver's
  for (const DriverBinding& d : p.drivers) {
    if (d.task != cell->task || !d.driver) continue;
    const auto& channels = d.driver->channels();
    for (std::size_t ch = 0; ch < d.bound_tags.size() && ch < channels.size(); ++ch) {
      if (d.bound_tags[ch] != parsed->base || channels[ch].dir != PinDir::In) continue;
      s.driver = d.driver.get();
      s.channel = static_cast<int>(ch);
      return s;
    }
  }
  return s;
}

}  // namespace syncplc::web
