// The contour-error metric of `syncplc sim --metrics` (docs/motion/contouring.md):
// the true contour error, the distance of the actual point (two axes' actual
// positions) from the reference path the project names, sampled with the
// motion metrics (metrics.hpp):
//   metrics:
//     contour: {axes: [pos[1], pos[2]], circle: {center: [0, 0], radius: 320 mm}}
//     contour: {axes: [px, py], line: {point: [0, 0], direction: [1, 1]}}
// For a circle the signed error is |r| - R (> 0 outside), for a line the
// distance to the right of its direction (> 0 right). The JSON reports the
// mean, maximum and RMS of its magnitude and its signed mean.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "runtime/core/config_node.hpp"
#include "runtime/core/program.hpp"
#include "runtime/project/diagnostics.hpp"

namespace syncplc {

struct ContourPath {
  enum class Kind { Circle, Line } kind = Kind::Circle;
  double cx = 0, cy = 0, radius = 0;  // circle
  double px = 0, py = 0, dx = 1, dy = 0;  // line: a point and a unit direction
};

// Signed distance of (x, y) from the path (see the header comment).
double contour_distance(const ContourPath& path, double x, double y);

// `metrics: contour:` as written: the two axes and the path.
struct ContourDecl {
  bool present = false;
  std::pair<std::string, SourceLoc> x, y;
  ContourPath path;
  SourceLoc loc;
};
void read_contour_metric(const ConfigNode& n, ContourDecl& out, Diagnostics& diags);

// Resolved: the cells of the two axes' actual positions.
struct ContourSettings {
  TraceColumn x, y;
  ContourPath path;
};
// Resolves the axes of `d` in `prog` (LREAL or REAL scalars, in `task`);
// nullopt with an error at the reference otherwise.
std::optional<ContourSettings> resolve_contour_metric(const ContourDecl& d, const Program& prog, std::uint16_t task,
                                                      Diagnostics& diags);

// The running statistics; add() does not allocate.
class ContourMetric {
 public:
  void add(double x, double y, const ContourPath& path) noexcept;
  std::uint64_t samples() const { return n_; }
  double mean_abs() const { return n_ ? sum_abs_ / static_cast<double>(n_) : 0.0; }
  double mean() const { return n_ ? sum_ / static_cast<double>(n_) : 0.0; }
  double max_abs() const { return max_abs_; }
  double rms() const;

 private:
  std::uint64_t n_ = 0;
  double sum_ = 0, sum_abs_ = 0, sum2_ = 0, max_abs_ = 0;
};

}  // namespace syncplc
