#include "runtime/project/metrics.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace syncplc {

MotionMetrics::MotionMetrics(const MetricsSettings& m) : from_ns_(m.from_ns), contour_(m.contour) {
  for (const auto& c : m.axis_errors) {
    errors_.push_back(c.ref);
    labels_.push_back(c.label);
  }
  if (!errors_.empty()) task_ = errors_.front().task;
  const std::size_t n = errors_.size();
  max_e_.assign(n, 0.0);
  sum_e2_.assign(n, 0.0);
  max_eps_.assign(n, 0.0);
  e_.assign(n, 0.0);
}

void MotionMetrics::sample(const Program& p, ImageAccess a, std::int64_t t, std::uint64_t owner_scans) {
  if (errors_.empty() || owner_scans == last_scans_) return;
  last_scans_ = owner_scans;
  if (t < from_ns_) return;
  const std::size_t n = errors_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = errors_[i];
    Cell c = p.tasks[r.task]->image(a)[r.cell];
    e_[i] = r.type == IecType::REAL ? static_cast<double>(c.get<float>()) : c.get<double>();
  }
  double track = 0, sync = 0, prefix = 0;
  for (std::size_t i = 0; i < n; ++i) {
    track += e_[i] * e_[i];
    sum_e2_[i] += e_[i] * e_[i];
    max_e_[i] = std::max(max_e_[i], std::abs(e_[i]));
    if (i > 0) {
      const double eps = e_[i] - prefix / static_cast<double>(i);  // row i of T, eq. (6)
      sync += eps * eps;
      max_eps_[i] = std::max(max_eps_[i], std::abs(eps));
    }
    prefix += e_[i];
  }
  sum_track_ += track;
  sum_sync_ += sync;
  ++n_;
  if (contour_) {
    auto value = [&](const CellRef& r) {
      Cell c = p.tasks[r.task]->image(a)[r.cell];
      return r.type == IecType::REAL ? static_cast<double>(c.get<float>()) : c.get<double>();
    };
    contour_error_.add(value(contour_->x.ref), value(contour_->y.ref), contour_->path);
  }
}

double MotionMetrics::track_rsme() const { return n_ ? std::sqrt(sum_track_ / static_cast<double>(n_)) : 0.0; }
double MotionMetrics::sync_rsme() const { return n_ ? std::sqrt(sum_sync_ / static_cast<double>(n_)) : 0.0; }
double MotionMetrics::rms_error(std::size_t axis) const {
  return n_ ? std::sqrt(sum_e2_[axis] / static_cast<double>(n_)) : 0.0;
}

std::string MotionMetrics::json(const Program& p, std::int64_t duration_ns, double wall_s) const {
  using nlohmann::ordered_json;
  ordered_json j;
  j["project"] = p.name;
  j["file"] = p.file;
  j["seed"] = p.seed;
  j["duration_s"] = static_cast<double>(duration_ns) * 1e-9;
  j["wall_s"] = wall_s;
  if (!errors_.empty()) {
    ordered_json m;
    m["samples"] = n_;
    m["from_s"] = static_cast<double>(from_ns_) * 1e-9;
    m["track_rsme"] = track_rsme();
    m["sync_rsme"] = sync_rsme();
    ordered_json axes = ordered_json::array();
    for (std::size_t i = 0; i < errors_.size(); ++i)
      axes.push_back({{"axis", i + 1},
                      {"error", labels_[i]},
                      {"max_abs_error", max_e_[i]},
                      {"rms_error", rms_error(i)},
                      {"max_abs_sync_error", max_eps_[i]}});
    m["axes"] = axes;
    if (contour_) {
      const ContourPath& path = contour_->path;
      ordered_json c;
      c["axes"] = {contour_->x.label, contour_->y.label};
      if (path.kind == ContourPath::Kind::Circle)
        c["path"] = {{"circle", {{"center", {path.cx, path.cy}}, {"radius", path.radius}}}};
      else
        c["path"] = {{"line", {{"point", {path.px, path.py}}, {"direction", {path.dx, path.dy}}}}};
      c["samples"] = contour_error_.samples();
      c["mean_abs"] = contour_error_.mean_abs();
      c["max_abs"] = contour_error_.max_abs();
      c["rms"] = contour_error_.rms();
      c["mean"] = contour_error_.mean();
      m["contour_error"] = c;
    }
    j["metrics"] = m;
  }
  ordered_json tasks = ordered_json::array();
  for (const auto& t : p.tasks) {
    auto s = t->stats.summary();
    auto hist = [](const Histogram::Summary& h) {
      return ordered_json{{"mean_ns", h.mean}, {"p50_ns", h.p50}, {"p99_ns", h.p99}, {"max_ns", h.max}};
    };
    tasks.push_back({{"name", t->config().name},
                     {"period_ns", t->config().period_ns},
                     {"scans", s.scans},
                     {"overruns", s.overruns},
                     {"skipped", s.skipped},
                     {"watchdog_trips", s.watchdog_trips},
                     {"exec", hist(s.exec)},
                     {"jitter", hist(s.jitter)}});
  }
  j["tasks"] = tasks;
  ordered_json drivers = ordered_json::array();
  for (const auto& d : p.drivers) {
    ordered_json c = ordered_json::object();
    for (const auto& [k, v] : d.driver->counters()) c[k] = v;
    drivers.push_back({{"name", d.driver->name()}, {"type", d.type}, {"counters", c}});
  }
  j["drivers"] = drivers;
  return j.dump(2) + "\n";
}

}  // namespace syncplc
