// The running program as the API shows it (docs/http-api.md, "Reading"):
// tasks with their statistics, tags and pins with their live values and
// forced flags. Called with the program held (PlcHost::with_program).
#pragma once

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <utility>

#include "runtime/core/histogram.hpp"
#include "runtime/core/program.hpp"

namespace syncplc::web {

// The forced elements, (task, cell), from one look at the force registry.
using ForcedCells = std::set<std::pair<std::uint16_t, std::uint32_t>>;
ForcedCells forced_cells(const Program& p);

// {"bounds_ns": [1000, 2000, 5000, ...], "counts": [n <= 1 us, ..., n > last]}:
// the log-linear histogram summed into 1-2-5 steps from 1 us to 1 s.
nlohmann::json histogram_json(const Histogram& h);
// {"upper_ns": [...], "counts": [...]}: the histogram's own non-empty buckets
// (32 per power of two: a bucket's upper bound is within 1/32 of its values),
// each with its largest value. Two snapshots' difference gives the
// percentiles of the time between them (GET /status?histograms=full).
nlohmann::json full_histogram_json(const Histogram& h);
// {"last_ns"?, "min_ns", "max_ns", "mean_ns", "p50_ns", "p99_ns", "count", "histogram", "full"?}
nlohmann::json statistics_json(const Histogram& h, bool full = false);
nlohmann::json task_json(const Task& t, const nlohmann::json& state, bool full_histograms = false);
nlohmann::json tag_json(const Program& p, const Tag& t, const ForcedCells& forced);
nlohmann::json instance_json(Program& p, const InstanceInfo& b, const ForcedCells& forced);

// A reference's live value: tags from the owner's publication, pins from
// the pin monitor (null while its monitoring starts); `forced` true when any
// element is.
struct RefValue {
  nlohmann::json value;
  bool forced = false;
};
RefValue ref_value(Program& p, const CellRef& r, const ForcedCells& forced);

}  // namespace syncplc::web
