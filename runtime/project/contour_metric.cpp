#include "runtime/project/contour_metric.hpp"

#include <algorithm>
#include <cmath>

#include "runtime/core/units.hpp"

namespace syncplc {
namespace contour_metric_read {

// [x, y] with optional length units, in the axes' unit (m if a unit is written).
bool point(const ConfigNode* n, const std::string& what, double& x, double& y, Diagnostics& diags) {
  if (!n || !n->is_list() || n->items.size() != 2 || !n->items[0].is_scalar() || !n->items[1].is_scalar()) {
    diags.error(n ? n->loc : SourceLoc{}, "metrics contour: " + what + " is written [x, y]");
    return false;
  }
  std::string err;
  auto a = parse_quantity(n->items[0].scalar, "m", &err);
  auto b = a ? parse_quantity(n->items[1].scalar, "m", &err) : std::nullopt;
  if (!a || !b || !std::isfinite(*a) || !std::isfinite(*b)) {
    diags.error(n->loc, "metrics contour: " + what + ": " + (err.empty() ? "not finite" : err));
    return false;
  }
  x = *a, y = *b;
  return true;
}

bool map_keys(const ConfigNode& n, const char* what, std::initializer_list<const char*> keys, Diagnostics& diags) {
  if (!n.is_map()) {
    diags.error(n.loc, std::string("metrics contour: ") + what + " is a map");
    return false;
  }
  bool ok = true;
  for (const auto& [k, v] : n.map) {
    bool known = false;
    for (const char* key : keys) known = known || k == key;
    if (!known) {
      std::string list;
      for (const char* key : keys) list += (list.empty() ? "" : ", ") + std::string(key);
      diags.error(v.loc, "unknown key '" + k + "' in metrics contour " + what + " (" + list + ")");
      ok = false;
    }
  }
  return ok;
}

}  // namespace contour_metric_read

double contour_distance(const ContourPath& p, double x, double y) {
  if (p.kind == ContourPath::Kind::Circle) return std::hypot(x - p.cx, y - p.cy) - p.radius;
  // Right of the direction: the component along (dy, -dx).
  return (x - p.px) * p.dy - (y - p.py) * p.dx;
}

void read_contour_metric(const ConfigNode& n, ContourDecl& out, Diagnostics& diags) {
  using namespace contour_metric_read;
  out.loc = n.loc;
  if (!map_keys(n, "", {"axes", "circle", "line"}, diags)) return;
  const ConfigNode* axes = n.find("axes");
  const ConfigNode* circle = n.find("circle");
  const ConfigNode* line = n.find("line");
  bool ok = true;
  if (!axes || !axes->is_list() || axes->items.size() != 2 || !axes->items[0].is_scalar() || !axes->items[1].is_scalar()) {
    diags.error(axes ? axes->loc : n.loc, "metrics contour: axes is a list of the two actual positions [x, y]");
    ok = false;
  } else {
    out.x = {axes->items[0].scalar, axes->items[0].loc};
    out.y = {axes->items[1].scalar, axes->items[1].loc};
  }
  if ((circle != nullptr) == (line != nullptr)) {
    diags.error(n.loc, "metrics contour: give the path as exactly one of circle: {center, radius} or line: {point, direction}");
    return;
  }
  if (circle) {
    out.path.kind = ContourPath::Kind::Circle;
    if (!map_keys(*circle, "circle", {"center", "radius"}, diags)) return;
    ok = point(circle->find("center"), "circle center", out.path.cx, out.path.cy, diags) && ok;
    const ConfigNode* r = circle->find("radius");
    std::string err;
    auto v = r && r->is_scalar() ? parse_quantity(r->scalar, "m", &err) : std::nullopt;
    if (!v || !(*v > 0) || !std::isfinite(*v)) {
      diags.error(r ? r->loc : circle->loc, "metrics contour: circle radius must be a positive length" + (err.empty() ? "" : ": " + err));
      ok = false;
    } else {
      out.path.radius = *v;
    }
  } else {
    out.path.kind = ContourPath::Kind::Line;
    if (!map_keys(*line, "line", {"point", "direction"}, diags)) return;
    ok = point(line->find("point"), "line point", out.path.px, out.path.py, diags) && ok;
    double dx = 0, dy = 0;
    if (point(line->find("direction"), "line direction", dx, dy, diags)) {
      const double len = std::hypot(dx, dy);
      if (!(len > 0)) {
        diags.error(line->find("direction")->loc, "metrics contour: line direction must not be [0, 0]");
        ok = false;
      } else {
        out.path.dx = dx / len, out.path.dy = dy / len;
      }
    } else {
      ok = false;
    }
  }
  out.present = ok;
}

std::optional<ContourSettings> resolve_contour_metric(const ContourDecl& d, const Program& prog, std::uint16_t task,
                                                      Diagnostics& diags) {
  if (!d.present) return std::nullopt;
  ContourSettings s;
  s.path = d.path;
  bool ok = true;
  for (auto [decl, col] : {std::pair{&d.x, &s.x}, std::pair{&d.y, &s.y}}) {
    std::string err;
    auto r = prog.resolve(decl->first, &err);
    if (!r) {
      diags.error(decl->second, "metrics contour: " + err);
      ok = false;
    } else if (r->length != 1 || (r->type != IecType::LREAL && r->type != IecType::REAL)) {
      diags.error(decl->second, "metrics contour: " + decl->first + " must be one REAL or LREAL value (an axis's actual position)");
      ok = false;
    } else if (r->task != task) {
      diags.error(decl->second, "metrics contour: " + decl->first + " belongs to another task than the axis_errors");
      ok = false;
    } else {
      *col = {decl->first, *r};
    }
  }
  if (!ok) return std::nullopt;
  return s;
}

void ContourMetric::add(double x, double y, const ContourPath& path) noexcept {
  const double e = contour_distance(path, x, y);
  ++n_;
  sum_ += e;
  sum_abs_ += std::abs(e);
  sum2_ += e * e;
  max_abs_ = std::max(max_abs_, std::abs(e));
}

double ContourMetric::rms() const { return n_ ? std::sqrt(sum2_ / static_cast<double>(n_)) : 0.0; }

}  // namespace syncplc
