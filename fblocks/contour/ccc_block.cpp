// CCC_2AXIS: cross-coupled contour control of two axes (paper 003 section
// 4.3, Fig. 10, and its robust CCC), with the contour error estimated from
// the reference path's tangent and curvature (Yeh & Hsu 2002). The math is
// in ccc_math.hpp; docs/motion/contouring.md derives it.
#include <cmath>
#include <memory>

#include "fblocks/contour/ccc.hpp"
#include "fblocks/contour/ccc_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::contour {
namespace ccc_block {

enum : int {
  kEnable = 0, kXRef, kYRef, kVxRef, kVyRef, kAxRef, kAyRef, kX, kY,         // inputs
  kEps, kUx, kUy, kCx, kCy, kCurvature, kGain, kActive,                     // outputs
};

// Parameter indices (declaration order in ccc_info).
enum : int { kPGain = 0, kPTi, kPRobust, kPGainLow, kPKRef, kPLimit, kPVMin };

struct Config {
  double gain = 0, ti = 0, gain_low = 0, k_ref = 0, limit = 0, v_min = 0;
  bool robust = false;
};

class Ccc2Axis final : public Block {
 public:
  explicit Ccc2Axis(const Config& c) : c_(c) {}

  // Every gain is tunable; the integral part is kept in output units (as in
  // PID), so a new gain or Ti does not bump the correction.
  void retune_from(const Block& fresh) noexcept override { apply(static_cast<const Ccc2Axis&>(fresh).c_); }
  bool tune(int param, double v) noexcept override {
    Config n = c_;
    switch (param) {
      case kPGain: n.gain = v; break;
      case kPTi: n.ti = v; break;
      case kPGainLow: n.gain_low = v; break;
      case kPKRef: n.k_ref = v; break;
      case kPLimit: n.limit = v; break;
      default: return false;
    }
    if (!std::isfinite(v) || v < 0) return false;
    apply(n);
    return true;
  }

  void execute(ScanContext& ctx) noexcept override {
    if (!in<bool>(kEnable)) {
      has_frame_ = false;
      integral_ = 0;
      emit(0, 0, 0, 0, 0, 0, 0, false);
      return;
    }
    // Standstill keeps the last direction of travel; none yet: inactive.
    if (path_frame(in<double>(kVxRef), in<double>(kVyRef), in<double>(kAxRef), in<double>(kAyRef), c_.v_min, frame_))
      has_frame_ = true;
    if (!has_frame_) {
      emit(0, 0, 0, 0, 0, 0, 0, false);
      return;
    }
    const double ex = in<double>(kXRef) - in<double>(kX);
    const double ey = in<double>(kYRef) - in<double>(kY);
    const double eps = contour_error(frame_, ex, ey);
    const CouplingGains cg = coupling_gains(frame_, ex, ey);
    const double k = std::abs(frame_.kappa);
    const double gain = c_.robust ? scheduled_gain(k, c_.gain_low, c_.gain, c_.k_ref) : c_.gain;
    const double v = gain * eps + integral_;
    const double u = c_.limit > 0 ? std::fmax(-c_.limit, std::fmin(v, c_.limit)) : v;
    const double h = ctx.dt_ns > 0 ? static_cast<double>(ctx.dt_ns) * 1e-9 : 0.0;
    if (c_.ti > 0 && h > 0) {
      const double inc = gain * h / c_.ti * eps;
      // Conditional integration: no increment that pushes a limited output further out.
      if (!(u != v && (v > 0) == (inc > 0))) integral_ += inc;
    }
    // The correction moves each axis against its share of the contour error:
    // d eps / d ex = -Cx, d eps / d ey = Cy, and a positive command lowers e.
    emit(eps, -cg.cx * u, cg.cy * u, cg.cx, cg.cy, k, gain, true);
  }

 private:
  void emit(double eps, double ux, double uy, double cx, double cy, double k, double gain, bool active) noexcept {
    out<double>(kEps, eps);
    out<double>(kUx, ux);
    out<double>(kUy, uy);
    out<double>(kCx, cx);
    out<double>(kCy, cy);
    out<double>(kCurvature, k);
    out<double>(kGain, gain);
    out<bool>(kActive, active);
  }
  void apply(const Config& n) noexcept {
    c_.gain = n.gain, c_.ti = n.ti, c_.gain_low = n.gain_low, c_.k_ref = n.k_ref, c_.limit = n.limit;
    if (!(c_.ti > 0)) integral_ = 0;  // no integral action: no bias left over either
  }

  Config c_;
  PathFrame frame_;
  bool has_frame_ = false;
  double integral_ = 0;  // integral part, in output units
};

double real_or_report(BlockSetup& s, const char* name, bool* ok) {
  const double v = s.param<double>(name);
  if (!std::isfinite(v) || v < 0) {
    s.error(s.type().name + ": parameter " + name + " must be finite and not negative");
    *ok = false;
  }
  return v;
}

std::unique_ptr<Block> make(BlockSetup& s) {
  bool ok = true;
  Config c;
  c.gain = real_or_report(s, "gain", &ok);
  c.ti = real_or_report(s, "Ti", &ok);
  c.robust = s.param<bool>("robust");
  c.gain_low = real_or_report(s, "gain_low", &ok);
  c.k_ref = real_or_report(s, "k_ref", &ok);
  c.limit = real_or_report(s, "limit", &ok);
  c.v_min = real_or_report(s, "v_min", &ok);
  if (ok && c.robust && !(c.k_ref > 0)) {
    s.error(s.type().name + ": robust needs k_ref > 0 (the curvature at which the gain reaches gain)");
    ok = false;
  }
  if (!ok) return nullptr;
  return std::make_unique<Ccc2Axis>(c);
}

BlockTypeInfo ccc_info() {
  BlockTypeInfo t;
  t.name = "CCC_2AXIS";
  t.category = "Motion";
  t.doc =
      "Cross-coupled contour control of two axes (paper 003 section 4.3, Fig. 10). From the reference "
      "velocity and acceleration: unit tangent t = v/|v| and signed curvature kappa = (vx ay - vy ax)/|v|^3 "
      "(held while |v| <= v_min; inactive until the reference first moves). With the tracking errors "
      "ex = x_ref - x, ey = y_ref - y, the contour error eps is the distance of the actual point from the "
      "path's circle of curvature at the reference point (Yeh & Hsu 2002), positive to the right of the "
      "direction of travel; it is exact on a straight line and on a circle (eps = |r| - R on an anticlockwise "
      "circle). Coupling gains Cx = sin th - kappa ex/2, Cy = cos th + kappa ey/2 (eps ~ -Cx ex + Cy ey). "
      "CCC law: u = LIMIT(-limit, Kc eps + I, limit) with I += Kc h/Ti eps (Ti = 0: none; conditional "
      "integration at the limit); the corrections ux = -Cx u, uy = Cy u are added to the axis controllers' "
      "outputs. robust: Kc = gain_low + (gain - gain_low) min(1, K/k_ref) with the curvature K = |kappa| "
      "(paper 003 prints K = |y''|/(1+y'^2)^(3/2), not the map from K to the gain: this linear map is "
      "syncplc's choice). Any length unit used consistently; u in the unit of the axis commands. "
      "enable FALSE: all outputs 0, integral cleared. See docs/motion/contouring.md.";
  t.reference =
      "Paper 003 (motion message estimator), section 4.3 and Figs. 10-15; Yeh & Hsu, IEEE/ASME Trans. "
      "Mechatronics 7(1), 2002; Koren, ASME J. Dyn. Sys. 1980 (cross-coupled control)";
  t.pins = {
      input("enable", IecType::BOOL).init("TRUE").doc("FALSE: outputs 0, the integral and the held tangent cleared"),
      input("x_ref", IecType::LREAL).unit("m").required().doc("reference position, axis x"),
      input("y_ref", IecType::LREAL).unit("m").required().doc("reference position, axis y"),
      input("vx_ref", IecType::LREAL).unit("m/s").required().doc("reference velocity, axis x"),
      input("vy_ref", IecType::LREAL).unit("m/s").required().doc("reference velocity, axis y"),
      input("ax_ref", IecType::LREAL).unit("m/s^2").doc("reference acceleration, axis x (for the curvature)"),
      input("ay_ref", IecType::LREAL).unit("m/s^2").doc("reference acceleration, axis y (for the curvature)"),
      input("x", IecType::LREAL).unit("m").required().doc("actual position, axis x"),
      input("y", IecType::LREAL).unit("m").required().doc("actual position, axis y"),
      output("eps", IecType::LREAL).unit("m").doc("estimated contour error, > 0 right of the direction of travel"),
      output("ux", IecType::LREAL).doc("correction to add to axis x's controller output (-Cx u)"),
      output("uy", IecType::LREAL).doc("correction to add to axis y's controller output (Cy u)"),
      output("cx", IecType::LREAL).doc("coupling gain Cx"),
      output("cy", IecType::LREAL).doc("coupling gain Cy"),
      output("curvature", IecType::LREAL).unit("1/m").doc("path curvature K = |kappa| at the reference point"),
      output("kc", IecType::LREAL).doc("the CCC gain Kc used this scan (scheduled when robust)"),
      output("active", IecType::BOOL).doc("TRUE once the reference has moved (a tangent is known)"),
  };
  t.params = {
      parameter("gain", IecType::LREAL).init("0").min(0.0).tunable()
          .doc("CCC gain Kc (command unit per length unit); robust: the gain at K >= k_ref"),
      parameter("Ti", IecType::LREAL).init("0").min(0.0).unit("s").tunable()
          .doc("integral time of the PI law; 0 = proportional only"),
      parameter("robust", IecType::BOOL).init("FALSE").doc("TRUE: paper 003's robust CCC, the gain scheduled by K"),
      parameter("gain_low", IecType::LREAL).init("0").min(0.0).tunable()
          .doc("robust: the gain on a straight path (K = 0)"),
      parameter("k_ref", IecType::LREAL).init("0").min(0.0).unit("1/m").tunable()
          .doc("robust: the curvature from which the gain is `gain`"),
      parameter("limit", IecType::LREAL).init("0").min(0.0).tunable()
          .doc("bound on |u| before distribution (0 = none)"),
      parameter("v_min", IecType::LREAL).init("1e-9").min(0.0).unit("m/s")
          .doc("reference speed below which the tangent and curvature are held"),
  };
  t.create = make;
  return t;
}

}  // namespace ccc_block
}  // namespace syncplc::contour

namespace syncplc {

void register_ccc_blocks(BlockRegistry& registry) { registry.add(contour::ccc_block::ccc_info()); }

}  // namespace syncplc
