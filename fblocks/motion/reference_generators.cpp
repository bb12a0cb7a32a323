// Reference generators for the motion examples and tests:
//  - COSINE_TRAJECTORY: x_d = offset + A (1 - cos w t), the reference of paper 000
//    (Fig. 4; peak speed A w, 753.98 rad/min = 4 pi rad/s with A = 4 pi rad, w = 1 rad/s).
//  - CIRCLE: the contour test of paper 002 (radius 320 mm, anticlockwise, feeds
//    2500 and 10000 mm/min), with an optional raised-cosine start and stop.
//  - STEP_RAMP_SEQUENCE: the discontinuous references of steps and ramps of
//    paper 004 (Fig. 5, Fig. 10), seeded random or scripted.
// Every generator evaluates its closed-form profile at the scan's planned
// release time (ScanContext::now_ns) relative to the scan on which `enable`
// became TRUE, so the reference does not drift with the number of scans and x,
// v, a are exact derivatives of one another. See docs/motion/reference-generators.md.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

#include "fblocks/motion/motion.hpp"
#include "runtime/core/pin_decl.hpp"
#include "runtime/core/sim_random.hpp"

namespace syncplc::motion {
namespace {

constexpr double kPi = std::numbers::pi;

// The input every generator shares.
Pin enable_input() {
  return input("enable", IecType::BOOL).init("TRUE")
             .doc("TRUE runs the profile from t = 0 on the scan it becomes TRUE; FALSE stops and resets it to the "
                  "start");
}

// Time since the scan `enable` became TRUE; nullopt while disabled.
class RunClock {
 public:
  std::optional<double> step(bool enable, std::int64_t now_ns) noexcept {
    if (!enable) {
      running_ = false;
      return std::nullopt;
    }
    if (!running_) {
      running_ = true;
      start_ = now_ns;
    }
    std::int64_t d = 0;
    if (__builtin_sub_overflow(now_ns, start_, &d) || d < 0) d = 0;
    return static_cast<double>(d) / 1e9;  // correctly rounded: 200 ms is exactly 0.2
  }

 private:
  bool running_ = false;
  std::int64_t start_ = 0;
};

// ---- COSINE_TRAJECTORY ------------------------------------------------------

class CosineTrajectory final : public Block {
  enum : int { kEnable = 0, kX, kV, kA, kDone };

 public:
  explicit CosineTrajectory(BlockSetup& s)
      : amp_(s.param<double>("amplitude")),
        w_(s.param<double>("omega")),
        cycles_(s.param<double>("cycles")),
        delay_(s.param<double>("delay")),
        offset_(s.param<double>("offset")) {
    if (!(w_ > 0)) s.error(s.type().name + ": omega must be positive");
    if (cycles_ < 0 || delay_ < 0) s.error(s.type().name + ": cycles and delay must not be negative");
  }

  // omega is tunable: the phase is phi = phi0 + w (tau - tau0), rebased at
  // each change to the phase of the last scan, so x stays continuous (the
  // next scan moves one normal step, at the new frequency).
  void retune_from(const Block& fresh) noexcept override { set_omega(static_cast<const CosineTrajectory&>(fresh).w_); }
  bool tune(int param, double v) noexcept override {
    if (param != kPOmega || !(v > 0)) return false;
    set_omega(v);
    return true;
  }

  void execute(ScanContext& ctx) noexcept override {
    double x = offset_, v = 0, a = 0;
    bool done = false;
    const auto t = clock_.step(in<bool>(kEnable), ctx.now_ns);
    if (!t) phi0_ = tau0_ = last_tau_ = 0;  // disabled: the next run starts at phase 0
    if (t) {
      const double tau = *t - delay_;
      last_tau_ = tau;
      if (tau >= 0) {  // the motion starts at tau = 0 (a = A w^2 from there)
        const double end = cycles_ > 0 ? 2 * kPi * cycles_ : 0;  // phase at the end, 0 = endless
        const double phi = phi0_ + w_ * (tau - tau0_);
        if (cycles_ > 0 && phi >= end) {
          x = offset_ + amp_ * (1 - std::cos(end));  // holds still at the end point
          done = true;
        } else {
          x = offset_ + amp_ * (1 - std::cos(phi));
          v = amp_ * w_ * std::sin(phi);
          a = amp_ * w_ * w_ * std::cos(phi);
        }
      }
    }
    out<double>(kX, x);
    out<double>(kV, v);
    out<double>(kA, a);
    out<bool>(kDone, done);
  }

 private:
  enum : int { kPOmega = 1 };  // parameter index of omega

  void set_omega(double w) noexcept {
    const double tau = std::fmax(last_tau_, 0.0);  // the phase does not run before tau = 0
    phi0_ += w_ * (tau - tau0_);
    tau0_ = tau;
    w_ = w;
  }

  double amp_, w_, cycles_, delay_, offset_;
  double phi0_ = 0, tau0_ = 0;  // phase base: phi = phi0 + w (tau - tau0)
  double last_tau_ = 0;         // tau of the last scan
  RunClock clock_;
};

BlockTypeInfo cosine_info() {
  BlockTypeInfo t;
  t.name = "COSINE_TRAJECTORY";
  t.category = kCategory;
  t.doc =
      "Cosine reference of paper 000 (Fig. 4): with tau = time since enable rose minus delay, "
      "x = offset + A (1 - cos w tau), v = A w sin w tau, a = A w^2 cos w tau for 0 < tau < cycles 2 pi / w; "
      "before it x = offset, after it x holds the end point (offset for whole cycles) with v = a = 0 and done. "
      "Peak speed A w at w tau = pi/2; the paper's 753.98 rad/min is A = 4 pi rad with w = 1 rad/s "
      "(4 pi rad/s). The acceleration steps from 0 to A w^2 at the start and from A w^2 cos(2 pi cycles) to 0 "
      "at the end (the cosine profile has no acceleration ramp). Any position unit: x in the unit of A, "
      "v in it per second, a per second squared. omega is tunable while running: the phase w tau is "
      "accumulated, so a new omega changes the speed without a jump of x.";
  t.reference = "Decentralized multi-axis synchronous control (paper 000), section 5 and Fig. 4";
  t.pins = {
      enable_input(),
      output("x", IecType::LREAL).doc("position x_d (unit of amplitude)"),
      output("v", IecType::LREAL).doc("velocity dx_d/dt (unit of amplitude per second)"),
      output("a", IecType::LREAL).doc("acceleration (unit of amplitude per second squared)"),
      output("done", IecType::BOOL).doc("TRUE once the cycles are complete (never if cycles = 0)"),
  };
  t.params = {
      parameter("amplitude", IecType::LREAL)
          .doc("A: half the stroke (x runs from offset to offset + 2A); paper 000: 4 pi rad"),
      parameter("omega", IecType::LREAL).min(1e-9).unit("rad/s").tunable()
          .doc("angular frequency w = 2 pi / period; paper 000: 1 rad/s; tunable: a change keeps the phase, so x stays "
               "continuous"),
      parameter("cycles", IecType::LREAL).init("1").min(0).doc("number of periods, fractions allowed; 0 = endless"),
      parameter("delay", IecType::LREAL).init("0").min(0).unit("s").doc("rest at offset this long after enable rises"),
      parameter("offset", IecType::LREAL).init("0").doc("start position"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<CosineTrajectory>(s); };
  return t;
}

// ---- CIRCLE -------------------------------------------------------------------

// Path length along the circle with a raised-cosine start and stop of length
// ta (0: none): s, ds/dt, d2s/dt2 at time t. Speed f, length l (l <= 0: endless).
struct PathProfile {
  double f = 0, l = 0, ta = 0, dur = 0;  // dur: end of the motion (infinite if endless)

  void init(double feed, double length, double ramp) {
    ta = ramp;
    l = length;
    f = feed;
    if (l > 0 && ta > 0) f = std::min(feed, l / ta);  // too short to cruise: lower the top speed
    dur = l > 0 ? l / f + ta : std::numeric_limits<double>::infinity();
  }
  // Start ramp from rest: s, v, a at u in [0, ta].
  void ramp(double u, double& s, double& v, double& a) const {
    const double q = kPi * u / ta;
    s = f / 2 * (u - ta / kPi * std::sin(q));
    v = f / 2 * (1 - std::cos(q));
    a = f * kPi / (2 * ta) * std::sin(q);
  }
  bool at(double t, double& s, double& v, double& a) const {  // true once finished
    if (t >= dur) {
      s = l, v = 0, a = 0;
      return true;
    }
    if (ta > 0 && t < ta) {
      ramp(t, s, v, a);
    } else if (ta > 0 && l > 0 && t > dur - ta) {
      ramp(dur - t, s, v, a);
      s = l - s;
      a = -a;
    } else {
      s = f * (t - ta / 2);
      v = f;
      a = 0;
    }
    return false;
  }
};

class Circle final : public Block {
  enum : int { kEnable = 0, kX, kY, kVx, kVy, kAx, kAy, kS, kDone };

 public:
  explicit Circle(BlockSetup& s)
      : r_(s.param<double>("radius")),
        cx_(s.param<double>("cx")),
        cy_(s.param<double>("cy")),
        th0_(s.param<double>("start_angle")),
        dir_(s.param<bool>("clockwise") ? -1.0 : 1.0) {
    const double feed = s.param<double>("feed"), turns = s.param<double>("turns"), ramp = s.param<double>("ramp_time");
    if (!(r_ > 0) || !(feed > 0)) s.error(s.type().name + ": radius and feed must be positive");
    if (turns < 0 || ramp < 0) s.error(s.type().name + ": turns and ramp_time must not be negative");
    path_.init(feed, 2 * kPi * r_ * turns, ramp);
  }

  void execute(ScanContext& ctx) noexcept override {
    double s = 0, sd = 0, sdd = 0;
    bool done = false;
    if (auto t = clock_.step(in<bool>(kEnable), ctx.now_ns)) done = path_.at(*t, s, sd, sdd);
    const double th = th0_ + dir_ * s / r_;
    const double c = std::cos(th), sn = std::sin(th);
    const double cen = sd * sd / r_;  // centripetal acceleration
    out<double>(kX, cx_ + r_ * c);
    out<double>(kY, cy_ + r_ * sn);
    out<double>(kVx, -dir_ * sd * sn);
    out<double>(kVy, dir_ * sd * c);
    out<double>(kAx, -cen * c - dir_ * sdd * sn);
    out<double>(kAy, -cen * sn + dir_ * sdd * c);
    out<double>(kS, s);
    out<bool>(kDone, done);
  }

 private:
  double r_, cx_, cy_, th0_, dir_;
  PathProfile path_;
  RunClock clock_;
};

BlockTypeInfo circle_info() {
  BlockTypeInfo t;
  t.name = "CIRCLE";
  t.category = kCategory;
  t.doc =
      "Circular contour of paper 002: x = cx + R cos th, y = cy + R sin th, th = start_angle + d s/R (d = +1 "
      "anticlockwise as in the paper, -1 clockwise), with path length s(t) from the scan enable rose: "
      "s = feed t for turns 2 pi R / feed, then hold (done). vx = -d s' sin th, vy = d s' cos th, "
      "ax = -(s'^2/R) cos th - d s'' sin th, ay = -(s'^2/R) sin th + d s'' cos th. ramp_time Ta > 0 adds a "
      "raised-cosine start and stop (s' = feed (1 - cos(pi t/Ta))/2, continuous acceleration): the motion "
      "then lasts turns 2 pi R / feed + Ta (feed is lowered to the length / Ta if the path is shorter than "
      "feed Ta). Paper 002: R = 320 mm, 2500 mm/min gives 48.255 s for one turn without ramp; its 48.656 s "
      "(and 12.164 s at 10000 mm/min, 1 ms) are 12164 interpolation periods, what a ramp of 100 periods "
      "adds (ramp_time 0.4 s at 4 ms).";
  t.reference = "IEEE 1394 distributed motion control (paper 002), section on the circle test, Figs. 9-10";
  t.pins = {
      enable_input(),
      output("x", IecType::LREAL).unit("m").doc("x position"),
      output("y", IecType::LREAL).unit("m").doc("y position"),
      output("vx", IecType::LREAL).unit("m/s").doc("x velocity"),
      output("vy", IecType::LREAL).unit("m/s").doc("y velocity"),
      output("ax", IecType::LREAL).unit("m/s^2").doc("x acceleration"),
      output("ay", IecType::LREAL).unit("m/s^2").doc("y acceleration"),
      output("s", IecType::LREAL).unit("m").doc("path length travelled"),
      output("done", IecType::BOOL).doc("TRUE once the turns are complete (never if turns = 0)"),
  };
  t.params = {
      parameter("radius", IecType::LREAL).min(1e-9).unit("m").doc("R; paper 002: 320 mm"),
      parameter("feed", IecType::LREAL).min(1e-12).unit("m/s")
          .doc("path speed; paper 002: 2500 mm/min (Ts 4 ms) and 10000 mm/min (Ts 1 ms)"),
      parameter("cx", IecType::LREAL).init("0").unit("m").doc("centre x"),
      parameter("cy", IecType::LREAL).init("0").unit("m").doc("centre y"),
      parameter("start_angle", IecType::LREAL).init("0").unit("rad")
          .doc("angle of the start point seen from the centre"),
      parameter("clockwise", IecType::BOOL).init("FALSE").doc("FALSE: anticlockwise (paper 002)"),
      parameter("turns", IecType::LREAL).init("1").min(0).doc("number of turns, fractions allowed; 0 = endless"),
      parameter("ramp_time", IecType::LREAL).init("0").min(0).unit("s")
          .doc("raised-cosine start and stop duration (0: the feed from the first scan)"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<Circle>(s); };
  return t;
}

// ---- STEP_RAMP_SEQUENCE -------------------------------------------------------

class StepRampSequence final : public Block {
  enum : int { kEnable = 0, kT, kValue, kSlope, kR, kRDot, kChanged, kSegment };

 public:
  explicit StepRampSequence(BlockSetup& s)
      : scripted_(s.param<std::int16_t>("mode") == 1),
        n_(s.pin_length(kT)),
        min_hold_(s.param<double>("min_hold")),
        max_hold_(s.param<double>("max_hold")),
        rmin_(s.param<double>("r_min")),
        rmax_(s.param<double>("r_max")),
        slope_max_(s.param<double>("slope_max")),
        p_ramp_(s.param<double>("ramp_probability")),
        seed_(s.seed()) {
    if (!(min_hold_ > 0)) s.error(s.type().name + ": min_hold must be positive");
    if (max_hold_ < min_hold_) s.error(s.type().name + ": max_hold must not be below min_hold");
    if (slope_max_ < 0 || p_ramp_ < 0 || p_ramp_ > 1)
      s.error(s.type().name + ": slope_max must not be negative, ramp_probability must be 0..1");
    if (rmax_ < rmin_) s.error(s.type().name + ": r_max must not be below r_min");
    restart();
  }

  void execute(ScanContext& ctx) noexcept override {
    const auto t = clock_.step(in<bool>(kEnable), ctx.now_ns);
    if (!t) {
      if (started_) restart();
      const double r0 = scripted_ ? in<double>(kValue, 0) : seg_v0_;
      emit(r0, 0.0, false, -1);
      return;
    }
    started_ = true;
    const std::int32_t before = seg_;
    double r = 0, rd = 0;
    if (scripted_) {
      std::int32_t i = seg_;
      while (i + 1 < static_cast<std::int32_t>(n_) && *t >= in<double>(kT, static_cast<std::uint32_t>(i + 1))) ++i;
      while (i >= 0 && *t < in<double>(kT, static_cast<std::uint32_t>(i))) --i;
      seg_ = i;
      if (i < 0) {
        r = in<double>(kValue, 0);
      } else {
        const auto k = static_cast<std::uint32_t>(i);
        rd = in<double>(kSlope, k);
        r = in<double>(kValue, k) + rd * (*t - in<double>(kT, k));
      }
    } else {
      if (seg_ < 0) seg_ = 0;  // the first random segment starts at t = 0
      for (int k = 0; k < kMaxCatchUp && *t >= seg_end_; ++k) {
        next_random(seg_end_);
        ++seg_;
      }
      rd = seg_slope_;
      r = seg_v0_ + rd * (*t - seg_start_);
    }
    emit(r, rd, seg_ != before, seg_);
  }

 private:
  void emit(double r, double rd, bool changed, std::int32_t seg) {
    out<double>(kR, r);
    out<double>(kRDot, rd);
    out<bool>(kChanged, changed);
    out<std::int32_t>(kSegment, seg);
  }

  // Back to the state before the first scan: same seed, same sequence.
  void restart() noexcept {
    started_ = false;
    seg_ = -1;
    rng_ = SimRandom(seed_);
    next_random(0.0);  // segment 0, active from t = 0
  }

  // Draws the random segment that starts at `start` (four draws per segment,
  // always, so the stream stays aligned whatever the parameters).
  void next_random(double start) noexcept {
    const double u_hold = rng_.uniform(), u_val = rng_.uniform(), u_kind = rng_.uniform(), u_slope = rng_.uniform();
    const double d = min_hold_ + (max_hold_ - min_hold_) * u_hold;
    seg_start_ = start;
    seg_end_ = start + d;
    seg_v0_ = rmin_ + (rmax_ - rmin_) * u_val;
    seg_slope_ = 0.0;
    if (u_kind < p_ramp_) {  // a ramp that stays within [r_min, r_max] over the segment
      const double lo = std::max(-slope_max_, (rmin_ - seg_v0_) / d);
      const double hi = std::min(slope_max_, (rmax_ - seg_v0_) / d);
      seg_slope_ = lo + (hi - lo) * u_slope;
    }
  }

  bool scripted_;
  std::uint32_t n_;
  double min_hold_, max_hold_, rmin_, rmax_, slope_max_, p_ramp_;
  std::uint64_t seed_;
  SimRandom rng_;  // splitmix64: a fixed, platform-independent stream (std distributions are not)
  RunClock clock_;
  bool started_ = false;
  std::int32_t seg_ = -1;  // active segment, -1 before the first
  double seg_start_ = 0, seg_end_ = 0, seg_v0_ = 0, seg_slope_ = 0;
};

BlockTypeInfo step_ramp_info() {
  BlockTypeInfo t;
  t.name = "STEP_RAMP_SEQUENCE";
  t.category = kCategory;
  t.doc =
      "Discontinuous reference of steps and ramps (paper 004 Figs. 5 and 10), the input the nonlinear filter "
      "expects: r = v_i + slope_i (t - t_i), r_dot = slope_i in segment i, t from the scan enable rose. "
      "mode 0 (random): segments last U[min_hold, max_hold] s, start at a value U[r_min, r_max], and with "
      "probability ramp_probability are ramps with a slope uniform within [-slope_max, slope_max] narrowed so "
      "that r stays within [r_min, r_max] over the segment, else steps (slope 0). The stream is splitmix64 "
      "from the instance seed (project seed mixed with the instance name): every instance differs, runs "
      "repeat, and segment times are continuous-time, independent of the scan period; a restart repeats the "
      "sequence. mode 1 (scripted): segment i starts at t[i] (non-decreasing) with value[i] and slope[i] "
      "(array pins of length segments, usually constants); before t[0], r = value[0] and r_dot = 0. changed is "
      "TRUE on the scan a new segment becomes active (the first one included); segment is its index (-1 "
      "before the first). While enable is FALSE, r rests at the first value with r_dot = 0.";
  t.reference = "Synchronous reference generation (paper 004), Figs. 1, 5 and 10";
  t.pins = {
      enable_input(),
      input("t", IecType::LREAL).unit("s").array("segments")
          .doc("scripted: start time of each segment, non-decreasing"),
      input("value", IecType::LREAL).array("segments").doc("scripted: r at the start of each segment"),
      input("slope", IecType::LREAL).array("segments").doc("scripted: r_dot during each segment, unit of r per second"),
      output("r", IecType::LREAL).doc("reference"),
      output("r_dot", IecType::LREAL).doc("reference slope (unit of r per second)"),
      output("changed", IecType::BOOL).doc("TRUE for one scan when a new segment begins"),
      output("segment", IecType::DINT).doc("index of the active segment, -1 before the first"),
  };
  t.params = {
      parameter("mode", IecType::INT).init("0").min(0).max(1)
          .doc("0 random (seeded), 1 scripted (array inputs t, value, slope)"),
      parameter("segments", IecType::DINT).init("1").min(1).max(4096)
          .doc("scripted: number of segments (length of t, value, slope)"),
      parameter("min_hold", IecType::LREAL).init("0.1").min(1e-3).unit("s").doc("random: shortest segment"),
      parameter("max_hold", IecType::LREAL).init("0.5").min(1e-3).unit("s")
          .doc("random: longest segment (paper 004: changes at least every half second)"),
      parameter("r_min", IecType::LREAL).init("-1").doc("random: lowest value of r"),
      parameter("r_max", IecType::LREAL).init("1").doc("random: highest value of r"),
      parameter("slope_max", IecType::LREAL).init("1").min(0).doc("random: largest |r_dot| (unit of r per second)"),
      parameter("ramp_probability", IecType::LREAL).init("0.5").min(0).max(1)
          .doc("random: share of segments that are ramps"),
  };
  t.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<StepRampSequence>(s); };
  return t;
}

}  // namespace

void register_reference_generators(BlockRegistry& r) {
  r.add(cosine_info());
  r.add(circle_info());
  r.add(step_ramp_info());
}

}  // namespace syncplc::motion
