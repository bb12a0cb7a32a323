// NURBS_PATH: a NURBS contour (paper 003 section 4.3, eqs. (7)-(8)) run at a
// programmed feed by the speed-controlled interpolator of Yeh & Hsu (1999).
// Execute's rising edge latches the curve (points, weights, knots), checks it
// and starts at its first point; every scan then advances the parameter by
// the second-order Taylor step of u(s) for the path step feed * override * dt
// and outputs position, velocity and acceleration per axis (what feed-forward
// and a cross-coupled contour controller need), the unit tangent, curvature,
// u and the measured feed error. The last step is shortened so the path ends
// exactly on the last control point. See docs/motion/nurbs.md.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "fblocks/contour/nurbs.hpp"
#include "fblocks/contour/nurbs_math.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc {
namespace nurbs_path {

using nurbs::NurbsCurve;
using nurbs::NurbsFault;
using nurbs::Vec3;

constexpr const char* kCategoryName = "Contouring";

class NurbsPath final : public Block {
  enum : int {
    kExecute = 0, kOverride, kPx, kPy, kPz, kW, kKnot,
    kX, kY, kZ, kVx, kVy, kVz, kAx, kAy, kAz, kTx, kTy, kTz, kCurv, kU, kFeedError, kDone, kBusy, kError, kErrorId
  };
  enum : int { kPFeed = 4 };  // parameter index of feed

 public:
  explicit NurbsPath(BlockSetup& s)
      : n_(s.param<std::int32_t>("points")),
        k_(s.param<std::int16_t>("order")),
        dim_(s.param<std::int16_t>("axes")),
        feed_(s.param<double>("feed")),
        curve_(std::clamp<std::int32_t>(n_, 1, kMaxPinLength), std::clamp<int>(k_, 1, nurbs::kNurbsMaxOrder)) {
    const auto knots = s.param<std::int32_t>("knots");
    if (n_ < k_)
      s.error("NURBS_PATH: points (" + std::to_string(n_) + ") must be at least the order k (" + std::to_string(k_) +
              ")");
    if (knots != n_ + k_)
      s.error("NURBS_PATH: knots must be points + order = " + std::to_string(n_ + k_) + " (is " +
              std::to_string(knots) + ")");
    if (!(feed_ > 0)) s.error("NURBS_PATH: feed must be positive");
    // The loader checks the ranges too; a factory must not trust them (ST, the harness).
    if (k_ < 2 || k_ > nurbs::kNurbsMaxOrder)
      s.error("NURBS_PATH: order must be 2.." + std::to_string(nurbs::kNurbsMaxOrder) + " (is " +
              std::to_string(k_) + ")");
    if (dim_ != 2 && dim_ != 3) s.error("NURBS_PATH: axes must be 2 or 3 (is " + std::to_string(dim_) + ")");
    if (n_ < 2 || n_ > static_cast<std::int32_t>(kMaxPinLength)) s.error("NURBS_PATH: points must be 2..4096");
  }

  void retune_from(const Block& fresh) noexcept override { feed_ = static_cast<const NurbsPath&>(fresh).feed_; }
  bool tune(int param, double v) noexcept override {
    if (param != kPFeed || !(v > 0)) return false;
    feed_ = v;
    return true;
  }

  void execute(ScanContext& ctx) noexcept override {
    const bool exec = in<bool>(kExecute);
    const bool rising = exec && !prev_exec_;
    prev_exec_ = exec;
    bool finished_now = false;
    if (rising) {
      start(ctx);
    } else if (busy_) {
      finished_now = advance(ctx);
    }
    // PLCopen: Done and Error stay while Execute is TRUE, and for one scan at
    // least when Execute is already FALSE.
    if (!exec && !busy_ && !rising && !finished_now && !error_now_) {
      done_ = false;
      error_ = false;
      error_id_ = 0;
    }
    error_now_ = false;
    emit();
  }

 private:
  // Latches and checks the curve, and places the path on its first point.
  void start(ScanContext& ctx) noexcept {
    for (int i = 0; i < n_; ++i) {
      const auto e = static_cast<std::uint32_t>(i);
      curve_.px()[i] = in<double>(kPx, e);
      curve_.py()[i] = in<double>(kPy, e);
      curve_.pz()[i] = dim_ == 3 ? in<double>(kPz, e) : 0.0;
      curve_.weights()[i] = in<double>(kW, e);
    }
    for (int i = 0; i < n_ + k_; ++i) curve_.knots()[i] = in<double>(kKnot, static_cast<std::uint32_t>(i));
    int where = 0;
    const NurbsFault f = curve_.validate(&where);
    done_ = false;
    feed_error_ = 0;
    if (f != NurbsFault::kNone) {
      busy_ = false;
      error_ = true;
      error_now_ = true;
      error_id_ = static_cast<std::uint16_t>(f);
      ctx.fault(nurbs::nurbs_fault_text(f), where + 1);
      vel_ = acc_ = {};
      return;
    }
    error_ = false;
    error_id_ = 0;
    busy_ = true;
    u_ = curve_.u_begin();
    span_ = -1;
    evaluate(speed());
    pos_ = curve_.point(0);  // the clamped curve starts on it (exactly, not up to rounding)
  }

  // One interpolation step; true when it ended the path.
  bool advance(ScanContext& ctx) noexcept {
    const double v = speed();
    const double ds = v * static_cast<double>(ctx.dt_ns) * 1e-9;
    const double u_next = nurbs::nurbs_advance(curve_, u_, ds, span_, d_[1], d_[2]);
    if (u_next >= curve_.u_end()) {  // the last step, shortened to end on the last point
      u_ = curve_.u_end();
      evaluate(v);
      pos_ = curve_.point(n_ - 1);
      vel_ = acc_ = {};
      busy_ = false;
      done_ = true;
      return true;
    }
    const Vec3 before = pos_;
    u_ = u_next;
    evaluate(v);
    if (ds > 0) {
      const Vec3 step{pos_.x - before.x, pos_.y - before.y, pos_.z - before.z};
      feed_error_ = nurbs::norm(step) / ds - 1;
    }
    return false;
  }

  // C, C', C'' at u_, and the motion at path speed v: velocity v t, the
  // acceleration v^2 (C'' - (C''.t) t) / |C'|^2 (normal: the speed is constant
  // along the path), tangent t = C'/|C'|, curvature |C' x C''| / |C'|^3.
  void evaluate(double v) noexcept {
    span_ = curve_.derivatives(u_, 2, d_, span_);
    pos_ = d_[0];
    const double len = nurbs::norm(d_[1]);
    if (len > 0) {
      tan_ = {d_[1].x / len, d_[1].y / len, d_[1].z / len};
      const double along = nurbs::dot(d_[2], tan_);
      const double f = v * v / (len * len);
      acc_ = {f * (d_[2].x - along * tan_.x), f * (d_[2].y - along * tan_.y), f * (d_[2].z - along * tan_.z)};
    } else {
      acc_ = {};
    }
    vel_ = {v * tan_.x, v * tan_.y, v * tan_.z};
    curvature_ = nurbs::nurbs_curvature(d_[1], d_[2]);
  }

  double speed() noexcept { return feed_ * std::max(in<double>(kOverride), 0.0); }

  void emit() noexcept {
    out<double>(kX, pos_.x);
    out<double>(kY, pos_.y);
    out<double>(kZ, pos_.z);
    out<double>(kVx, vel_.x);
    out<double>(kVy, vel_.y);
    out<double>(kVz, vel_.z);
    out<double>(kAx, acc_.x);
    out<double>(kAy, acc_.y);
    out<double>(kAz, acc_.z);
    out<double>(kTx, tan_.x);
    out<double>(kTy, tan_.y);
    out<double>(kTz, tan_.z);
    out<double>(kCurv, curvature_);
    out<double>(kU, u_);
    out<double>(kFeedError, feed_error_);
    out<bool>(kDone, done_);
    out<bool>(kBusy, busy_);
    out<bool>(kError, error_);
    out<std::uint16_t>(kErrorId, error_id_);
  }

  std::int32_t n_;
  std::int16_t k_, dim_;
  double feed_;
  NurbsCurve curve_;  // sized here: the scan only writes into it
  Vec3 d_[3];         // C, C', C'' at u_
  Vec3 pos_, vel_, acc_, tan_;
  double curvature_ = 0, u_ = 0, feed_error_ = 0;
  int span_ = -1;
  bool prev_exec_ = false, busy_ = false, done_ = false, error_ = false, error_now_ = false;
  std::uint16_t error_id_ = 0;
};

BlockTypeInfo nurbs_path_info() {
  BlockTypeInfo t;
  t.name = "NURBS_PATH";
  t.category = kCategoryName;
  t.doc =
      "NURBS contour interpolator (paper 003 section 4.3): C(u) = sum R_i,k(u) V_i with the rational basis "
      "R_i,k = Z_i,k w_i / sum Z_j,k w_j (eqs. 7-8; Z by the Cox-de Boor recursion), run at the path speed "
      "feed * override by the speed-controlled interpolator of Yeh & Hsu (1999): every scan "
      "u+ = u + ds/|C'| - ds^2 (C'.C'')/(2 |C'|^4), ds = feed * override * dt (second-order Taylor of u(s), "
      "a step that crosses a knot split there; "
      "relative feed error ds^2/6 [(|C''|^2 + C'.C''')/|C'|^4 - 4 (C'.C'')^2/|C'|^6] - K^2 ds^2/24, measured "
      "on the chord). The rising edge of Execute latches the points (px, py, pz when axes = 3), weights w and "
      "knot vector, checks them (non-decreasing, clamped: the first and last k knots equal, interior knots "
      "repeated at most k-1 times, weights > 0, finite; a fault sets Error, ErrorID 1-6 and a BlockFault event "
      "naming the element) and starts on the first point; the last step is shortened so the path ends exactly "
      "on the last point (Done). Outputs per axis: position, velocity feed t and acceleration "
      "feed^2 (C'' - (C''.t) t)/|C'|^2 at constant feed (the feed jumps at the start and end: no ramp), the "
      "unit tangent t, the curvature K = |C' x C''|/|C'|^3 (|x'y'' - y'x''|/|C'|^3 in the plane; paper 003's "
      "K = |y''|/(1 + y'^2)^1.5 is its case x = u), u, and feed_error = |C(u+) - C(u)|/ds - 1 of the last "
      "full step. Units: points in m, feed in m/s (2500 mm/min is accepted).";
  t.reference = "Motion message estimator (paper 003) section 4.3, eqs. (7)-(8); Yeh & Hsu 1999, the "
                "speed-controlled interpolator for machining parametric curves";
  t.pins = {
      input("Execute", IecType::BOOL).doc("rising edge: latch and check the curve, start on its first point"),
      input("override", IecType::LREAL).init("1")
          .doc("feed override factor (1 = the programmed feed, 0 = feed hold; negative counts as 0)"),
      input("px", IecType::LREAL).unit("m").array("points").doc("control points V_i: x"),
      input("py", IecType::LREAL).unit("m").array("points").doc("control points V_i: y"),
      input("pz", IecType::LREAL).unit("m").array("points").doc("control points V_i: z (read only when axes = 3)"),
      input("w", IecType::LREAL).init("1").array("points").doc("weights w_i (> 0) of eq. (8)"),
      input("knot", IecType::LREAL).array("knots")
          .doc("knot vector: non-decreasing, clamped (first and last k knots equal), length points + order"),
      output("x", IecType::LREAL).unit("m").doc("x position C_x(u)"),
      output("y", IecType::LREAL).unit("m").doc("y position"),
      output("z", IecType::LREAL).unit("m").doc("z position (0 when axes = 2)"),
      output("vx", IecType::LREAL).unit("m/s").doc("x velocity: feed * override * t_x (0 when stopped)"),
      output("vy", IecType::LREAL).unit("m/s").doc("y velocity"),
      output("vz", IecType::LREAL).unit("m/s").doc("z velocity"),
      output("ax", IecType::LREAL).unit("m/s^2").doc("x acceleration at constant feed (normal to the path)"),
      output("ay", IecType::LREAL).unit("m/s^2").doc("y acceleration"),
      output("az", IecType::LREAL).unit("m/s^2").doc("z acceleration"),
      output("tx", IecType::LREAL).doc("unit tangent C'/|C'|: x"),
      output("ty", IecType::LREAL).doc("unit tangent: y"),
      output("tz", IecType::LREAL).doc("unit tangent: z"),
      output("curvature", IecType::LREAL).unit("1/m").doc("K = |C' x C''| / |C'|^3"),
      output("u", IecType::LREAL).doc("curve parameter"),
      output("feed_error", IecType::LREAL)
          .doc("relative feed error of the last full step: chord / (feed override dt) - 1"),
      output("Done", IecType::BOOL).doc("the path reached its last point (held while Execute is TRUE)"),
      output("Busy", IecType::BOOL).doc("the path is running"),
      output("Error", IecType::BOOL).doc("the curve latched at Execute is invalid (see ErrorID)"),
      output("ErrorID", IecType::UINT)
          .doc("1 knots decrease, 2 weight <= 0, 3 not clamped, 4 empty range, 5 interior knot repeated k times, "
               "6 not finite"),
  };
  t.params = {
      parameter("points", IecType::DINT).init("3").min(2).max(4096)
          .doc("number of control points n + 1 (array pin length)"),
      parameter("order", IecType::INT).init("3").min(2).max(nurbs::kNurbsMaxOrder)
          .doc("order k (degree k - 1): 3 quadratic, 4 cubic"),
      parameter("knots", IecType::DINT).init("6").min(4).max(4096 + nurbs::kNurbsMaxOrder)
          .doc("length of the knot vector: must equal points + order"),
      parameter("axes", IecType::INT).init("2").min(2).max(3).doc("2: x, y; 3: x, y, z"),
      parameter("feed", IecType::LREAL).min(1e-12).unit("m/s").tunable()
          .doc("programmed feedrate along the path (e.g. 2500 mm/min); tunable"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<NurbsPath>(s); };
  return t;
}

}  // namespace nurbs_path

void register_nurbs_blocks(BlockRegistry& r) { r.add(nurbs_path::nurbs_path_info()); }

}  // namespace syncplc
