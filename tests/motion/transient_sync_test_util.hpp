// Test rig for TRANSIENT_SYNC: one instance under test and one with rule = off
// (n independent filters) run in lockstep on the same references, with every
// scan checked against the nominal bounds and every transient window measured
// from the outputs (arrival scans, spread, energy) independently of the
// block's own window outputs, which are compared with the measurement.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include <cmath>
#include <limits>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block_harness.hpp"

namespace syncplc::motion::synctest {

struct AxisBounds {
  double a_min, a_max, v_min, v_max;
};

// Table II of paper 004 (U-, U+, xdot-, xdot+).
inline const std::vector<AxisBounds>& table2() {
  static const std::vector<AxisBounds> t = {{-25, 40, -6, 6}, {-20, 25, -5, 4}, {-30, 20, -4, 5}};
  return t;
}
// n axes cycling through the rows of Table II.
inline std::vector<AxisBounds> table2_cycled(int n) {
  std::vector<AxisBounds> b;
  for (int i = 0; i < n; ++i) b.push_back(table2()[static_cast<std::size_t>(i % 3)]);
  return b;
}

constexpr int kUnified = 0, kPaper = 1, kOff = 2;

// One instance and direct pointers to its pin cells.
class Instance {
 public:
  Instance(int n, int rule, std::int64_t period_ns, bool r_dot_connected = true)
      : n_(n), h_(builtin_blocks(), "TRANSIENT_SYNC", options(n, rule, period_ns, r_dot_connected)) {
    if (!h_.ok()) return;
    for (const char* p : {"r", "r_dot", "v_min", "v_max", "a_min", "a_max", "x", "x_dot", "x_ddot",
                          "v_min_applied", "v_max_applied", "tracking", "steps_to_go", "error"})
      base_.push_back(&h_.cell(p, 0));
  }
  bool ok() const { return h_.ok(); }
  std::string errors() const {
    std::string s;
    for (const auto& e : h_.errors()) s += e + "\n";
    return s;
  }
  BlockHarness& harness() { return h_; }
  void set_bounds(const std::vector<AxisBounds>& b) {
    for (int i = 0; i < n_; ++i) {
      a(kVMin, i).set(b[static_cast<std::size_t>(i)].v_min);
      a(kVMax, i).set(b[static_cast<std::size_t>(i)].v_max);
      a(kAMin, i).set(b[static_cast<std::size_t>(i)].a_min);
      a(kAMax, i).set(b[static_cast<std::size_t>(i)].a_max);
    }
  }
  void set_ref(int i, double r, double r_dot) {
    a(kR, i).set(r);
    a(kRDot, i).set(r_dot);
  }
  void scan() { h_.scan(); }
  double x(int i) const { return a(kX, i).get<double>(); }
  double x_dot(int i) const { return a(kXDot, i).get<double>(); }
  double x_ddot(int i) const { return a(kXDDot, i).get<double>(); }
  double v_min_applied(int i) const { return a(kVMinA, i).get<double>(); }
  double v_max_applied(int i) const { return a(kVMaxA, i).get<double>(); }
  bool tracking(int i) const { return a(kTrk, i).get<bool>(); }
  std::int64_t steps_to_go(int i) const { return a(kSteps, i).get<std::int64_t>(); }
  bool error(int i) const { return a(kErr, i).get<bool>(); }
  template <class T>
  T scalar(const char* pin) {
    return h_.get<T>(pin);
  }

 private:
  enum { kR, kRDot, kVMin, kVMax, kAMin, kAMax, kX, kXDot, kXDDot, kVMinA, kVMaxA, kTrk, kSteps, kErr };
  static BlockHarness::Options options(int n, int rule, std::int64_t period_ns, bool r_dot_connected) {
    BlockHarness::Options o;
    o.params = {{"n", std::to_string(n)}, {"rule", std::to_string(rule)}};
    o.period_ns = period_ns;
    if (!r_dot_connected)
      o.connected = std::set<std::string>{"r", "v_min", "v_max", "a_min", "a_max", "x0", "v0", "reset"};
    return o;
  }
  Cell& a(int pin, int i) const { return base_[static_cast<std::size_t>(pin)][i]; }

  int n_;
  BlockHarness h_;
  std::vector<Cell*> base_;
};

// A transient window as measured from the outputs.
struct Window {
  std::int64_t start = 0;        // scan at which synchronized fell
  std::int64_t length = 0;       // scans until synchronized rose again
  std::int64_t predicted = 0;    // the arrival output at the opening scan (t_M)
  std::int64_t spread = 0;       // latest minus earliest arrival of the axes that moved
  int moved = 0;                 // axes that did not track at some scan of the window
  double energy = 0;             // T * sum of x_dot^2 over the window's scans and the axes
  std::int64_t slowest_own = 0;  // largest steps_to_go at the opening scan
  std::vector<std::int64_t> own;       // per axis: steps_to_go at the opening scan
  std::vector<std::int64_t> arrival;   // per axis: scans from the opening to its last arrival (-1: did not move)
};

// Measures windows of one instance.
class WindowMeter {
 public:
  explicit WindowMeter(int n) : n_(n), last_rise_(static_cast<std::size_t>(n)), moved_(static_cast<std::size_t>(n)),
                                was_tracking_(static_cast<std::size_t>(n), true) {}

  // Call after each scan with the outputs. Returns true when a window closed.
  bool observe(Instance& in, std::int64_t scan, double T) {
    bool all = true;
    for (int i = 0; i < n_; ++i) all = all && in.tracking(i);
    bool closed = false;
    if (!open_ && !all) {
      open_ = true;
      cur_ = Window{};
      cur_.start = scan;
      cur_.predicted = in.scalar<std::int64_t>("arrival");
      cur_.own.assign(static_cast<std::size_t>(n_), 0);
      cur_.arrival.assign(static_cast<std::size_t>(n_), -1);
      for (int i = 0; i < n_; ++i) {
        moved_[static_cast<std::size_t>(i)] = false;
        last_rise_[static_cast<std::size_t>(i)] = -1;
        cur_.slowest_own = std::max(cur_.slowest_own, in.steps_to_go(i));
        cur_.own[static_cast<std::size_t>(i)] = in.steps_to_go(i);
      }
    }
    if (open_) {
      for (int i = 0; i < n_; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const bool t = in.tracking(i);
        if (!t) moved_[k] = true;
        if (t && !was_tracking_[k]) last_rise_[k] = scan;
      }
      if (all) {
        open_ = false;
        closed = true;
        cur_.length = scan - cur_.start;
        std::int64_t lo = INT64_MAX, hi = -1;
        for (int i = 0; i < n_; ++i) {
          const auto k = static_cast<std::size_t>(i);
          if (!moved_[k]) continue;
          ++cur_.moved;
          cur_.arrival[k] = last_rise_[k] - cur_.start;
          lo = std::min(lo, last_rise_[k]);
          hi = std::max(hi, last_rise_[k]);
        }
        cur_.spread = hi >= 0 ? hi - lo : 0;
        windows.push_back(cur_);
      } else {
        double e = 0;
        for (int i = 0; i < n_; ++i) e += in.x_dot(i) * in.x_dot(i);
        cur_.energy += e * T;
      }
    }
    for (int i = 0; i < n_; ++i) was_tracking_[static_cast<std::size_t>(i)] = in.tracking(i);
    return closed;
  }
  bool open() const { return open_; }
  std::vector<Window> windows;

 private:
  int n_;
  bool open_ = false;
  Window cur_;
  std::vector<std::int64_t> last_rise_;
  std::vector<bool> moved_;
  std::vector<bool> was_tracking_;
};

// Counts bound violations of one instance against the nominal bounds. A
// velocity beyond a bound that was just reduced at run time below it is
// allowed while the filter brakes towards the bound at full acceleration (or
// lands on it).
struct BoundChecker {
  std::int64_t violations = 0;
  std::string first;
  void check(Instance& in, const std::vector<AxisBounds>& b, std::int64_t scan, double T) {
    for (std::size_t i = 0; i < b.size(); ++i) {
      const int k = static_cast<int>(i);
      const double vt = 1e-12 * (1 + std::fabs(b[i].v_min) + std::fabs(b[i].v_max));
      const double at = 1e-7 * std::fmax(b[i].a_max, -b[i].a_min) * (1 + 1e-9);
      const double v = in.x_dot(k), a = in.x_ddot(k), lo = in.v_min_applied(k), hi = in.v_max_applied(k);
      const bool v_ok = (v >= b[i].v_min - vt || a >= b[i].a_max - at || v + T * a >= b[i].v_min - vt) &&
                        (v <= b[i].v_max + vt || a <= b[i].a_min + at || v + T * a <= b[i].v_max + vt);
      const bool ok = v_ok && a >= b[i].a_min - at && a <= b[i].a_max + at && lo >= b[i].v_min && hi <= b[i].v_max &&
                      lo < hi && !in.error(k);
      if (!ok && violations++ == 0) {
        std::ostringstream os;
        os << "scan " << scan << " axis " << i << ": x_dot " << v << " x_ddot " << a << " applied [" << lo << ", "
           << hi << "] nominal v [" << b[i].v_min << ", " << b[i].v_max << "] a [" << b[i].a_min << ", "
           << b[i].a_max << "] error " << in.error(k);
        first = os.str();
      }
    }
  }
};

// steps_to_go is exact: between two changes of the references or bounds (of
// any axis), an axis's steps_to_go falls by one per scan and the axis begins
// tracking on the scan it named. This holds for every axis of independent
// filters (Table I) and, under the unified rule, for the synchronized axes,
// whose steps_to_go is the common arrival t_M. Mismatches are counted.
struct CountdownChecker {
  std::int64_t mismatches = 0;
  std::string first;
  std::vector<std::int64_t> expect;  // per axis: the scan it should begin tracking on (-1: none)
  void reset(int n) { expect.assign(static_cast<std::size_t>(n), -1); }
  void check(Instance& in, int n, std::int64_t scan) {
    if (expect.size() != static_cast<std::size_t>(n)) reset(n);
    for (int i = 0; i < n; ++i) {
      std::int64_t& e = expect[static_cast<std::size_t>(i)];
      const std::int64_t st = in.steps_to_go(i);
      const std::int64_t named = in.tracking(i) ? scan : (st < 0 ? -1 : scan + st);
      if (e >= 0 && named != e && mismatches++ == 0) {
        std::ostringstream os;
        os << "scan " << scan << " axis " << i << ": steps_to_go " << st << " tracking " << in.tracking(i)
           << ", expected to begin tracking on scan " << e;
        first = os.str();
      }
      e = in.tracking(i) ? -1 : named;
    }
  }
};

// No overshoot: an axis that meets a step (a segment of slope 0) from rest
// approaches it from one side and never comes back out: x - r keeps its sign
// (or is 0) and |x - r| never grows, up to 1e-12 m of rounding, until the
// next change. Violations are counted.
struct OvershootChecker {
  std::int64_t violations = 0;
  std::string first;
  std::vector<double> last;  // per axis: |x - r| at the previous scan, NaN: not watched
  std::vector<int> side;     // per axis: sign of x - r when the step came
  void reset(int n) {
    last.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
    side.assign(static_cast<std::size_t>(n), 0);
  }
  // At the scan of a change: watch axis i if it meets a step from rest.
  void watch(int i, bool from_rest, bool step, double y) {
    const auto k = static_cast<std::size_t>(i);
    last[k] = from_rest && step ? std::fabs(y) : std::numeric_limits<double>::quiet_NaN();
    side[k] = y > 0 ? 1 : (y < 0 ? -1 : 0);
  }
  void check(int i, double y, std::int64_t scan) {
    const auto k = static_cast<std::size_t>(i);
    if (std::isnan(last[k])) return;
    const bool crossed = side[k] * y < -1e-12;
    const bool grew = std::fabs(y) > last[k] + 1e-12;
    if ((crossed || grew) && violations++ == 0) {
      std::ostringstream os;
      os << "scan " << scan << " axis " << i << ": x - r = " << y << (crossed ? " crossed the step" : " grew from ")
         << (crossed ? "" : std::to_string(last[k]));
      first = os.str();
    }
    last[k] = std::fmin(last[k], std::fabs(y));
  }
};

// Random steps and ramps for n axes, references changed at common events; the
// instance under test and the unsynchronized one see the same sequence. The
// next event comes once both have synchronized and held for a random time, so
// every transient of the sequence runs to its end.
class LockstepRig {
 public:
  LockstepRig(int n, int rule, double T, std::vector<AxisBounds> bounds, std::uint64_t seed)
      : n_(n), rule_(rule), T_(T), bounds_(std::move(bounds)), rng_(seed),
        test_(n, rule, static_cast<std::int64_t>(std::llround(T * 1e9))),
        off_(n, kOff, static_cast<std::int64_t>(std::llround(T * 1e9))), meter_test_(n), meter_off_(n),
        r_(static_cast<std::size_t>(n), 0.0), s_(static_cast<std::size_t>(n), 0.0) {
    test_.set_bounds(bounds_);
    off_.set_bounds(bounds_);
  }
  bool ok() const { return test_.ok() && off_.ok(); }
  std::string errors() const { return test_.errors() + off_.errors(); }

  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  bool chance(double p) { return uni(0, 1) < p; }

  // A new random segment for axis i: a step (large, or 10 % tiny) and a ramp
  // of at most ramp_frac of the velocity bound on its side (40 % constant).
  void random_segment(int i, double max_step, double ramp_frac) {
    const auto k = static_cast<std::size_t>(i);
    changed_ = true;
    moved_[k] = true;
    still_[k] = s_[k] == 0;  // the segment it leaves is a step: at rest if it tracks
    const double sign = chance(0.5) ? 1 : -1;
    const double mag = chance(0.1) ? uni(0.0005, 0.02) : uni(0.05, max_step);
    r_[k] += sign * mag;
    if (chance(0.4)) s_[k] = 0;
    else s_[k] = chance(0.5) ? uni(0, ramp_frac) * bounds_[k].v_max : uni(0, ramp_frac) * bounds_[k].v_min;
  }
  // New nominal bounds for axis i (both instances), from this scan on.
  void set_axis_bounds(int i, const AxisBounds& b) {
    changed_ = true;
    bounds_[static_cast<std::size_t>(i)] = b;
    test_.set_bounds(bounds_);
    off_.set_bounds(bounds_);
  }
  const AxisBounds& axis_bounds(int i) const { return bounds_[static_cast<std::size_t>(i)]; }
  void set_segment(int i, double r, double s) {
    changed_ = true;
    moved_[static_cast<std::size_t>(i)] = true;
    still_[static_cast<std::size_t>(i)] = s_[static_cast<std::size_t>(i)] == 0;
    r_[static_cast<std::size_t>(i)] = r;
    s_[static_cast<std::size_t>(i)] = s;
  }
  double ref(int i) const { return r_[static_cast<std::size_t>(i)]; }
  double slope(int i) const { return s_[static_cast<std::size_t>(i)]; }

  void scan() {
    for (int i = 0; i < n_; ++i) {
      test_.set_ref(i, r_[static_cast<std::size_t>(i)], s_[static_cast<std::size_t>(i)]);
      off_.set_ref(i, r_[static_cast<std::size_t>(i)], s_[static_cast<std::size_t>(i)]);
    }
    test_.scan();
    off_.scan();
    check_test_.check(test_, bounds_, scan_, T_);
    check_off_.check(off_, bounds_, scan_, T_);
    if (changed_) {
      countdown_test_.reset(n_);
      countdown_off_.reset(n_);
      if (overshoot_test_.last.empty()) {
        overshoot_test_.reset(n_);
        overshoot_off_.reset(n_);
      }
      // The outputs at this scan are the states before the change took effect
      // (x moves from the next scan on): "from rest" is the previous scan's tracking.
      for (int i = 0; i < n_; ++i) {
        const auto k = static_cast<std::size_t>(i);
        if (moved_[k]) {
          overshoot_test_.watch(i, was_tracking_test_[k] && still_[k], s_[k] == 0, test_.x(i) - r_[k]);
          overshoot_off_.watch(i, was_tracking_off_[k] && still_[k], s_[k] == 0, off_.x(i) - r_[k]);
        } else if (s_[k] != 0) {
          overshoot_test_.watch(i, false, false, 0);
          overshoot_off_.watch(i, false, false, 0);
        }
        moved_[k] = false;
      }
      changed_ = false;
    }
    if (!overshoot_test_.last.empty())
      for (int i = 0; i < n_; ++i) {
        overshoot_test_.check(i, test_.x(i) - r_[static_cast<std::size_t>(i)], scan_);
        overshoot_off_.check(i, off_.x(i) - r_[static_cast<std::size_t>(i)], scan_);
      }
    for (int i = 0; i < n_; ++i) {
      was_tracking_test_[static_cast<std::size_t>(i)] = test_.tracking(i);
      was_tracking_off_[static_cast<std::size_t>(i)] = off_.tracking(i);
    }
    if (rule_ == kUnified) countdown_test_.check(test_, n_, scan_);
    countdown_off_.check(off_, n_, scan_);
    meter_test_.observe(test_, scan_, T_);
    meter_off_.observe(off_, scan_, T_);
    if (meter_test_.windows.size() > compared_) compare_block_outputs();
    for (int i = 0; i < n_; ++i) r_[static_cast<std::size_t>(i)] += T_ * s_[static_cast<std::size_t>(i)];
    ++scan_;
  }

  // Scans until neither instance has an open window (at most cap scans);
  // false on timeout.
  bool settle(std::int64_t cap) {
    for (std::int64_t k = 0; k < cap; ++k) {
      scan();
      if (!meter_test_.open() && !meter_off_.open()) return true;
    }
    return false;
  }

  Instance& test() { return test_; }
  Instance& off() { return off_; }
  const std::vector<Window>& windows_test() const { return meter_test_.windows; }
  const std::vector<Window>& windows_off() const { return meter_off_.windows; }
  const BoundChecker& bounds_test() const { return check_test_; }
  const BoundChecker& bounds_off() const { return check_off_; }
  // steps_to_go against the scans the axes began tracking on (the unified
  // rule's instance; the paper's parked axes arrive when they do).
  const CountdownChecker& countdown_test() const { return countdown_test_; }
  const CountdownChecker& countdown_off() const { return countdown_off_; }
  const OvershootChecker& overshoot_test() const { return overshoot_test_; }
  const OvershootChecker& overshoot_off() const { return overshoot_off_; }
  std::int64_t scans() const { return scan_; }
  // Block outputs disagreeing with the measured window (count, first message).
  std::int64_t output_mismatches = 0;
  std::string first_mismatch;

 private:
  void compare_block_outputs() {
    const Window& w = meter_test_.windows.back();
    compared_ = meter_test_.windows.size();
    const double e = test_.scalar<double>("energy_last");
    const auto spread = test_.scalar<std::int64_t>("spread");
    const auto len = test_.scalar<std::int64_t>("window_scans");
    const auto count = test_.scalar<std::int64_t>("windows");
    const bool ok = std::fabs(e - w.energy) <= 1e-9 * (1 + w.energy) && spread == w.spread && len == w.length &&
                    count == static_cast<std::int64_t>(meter_test_.windows.size()) &&
                    test_.scalar<double>("energy") == e;
    if (!ok && output_mismatches++ == 0) {
      std::ostringstream os;
      os << "window " << compared_ << ": energy_last " << e << " vs " << w.energy << ", spread " << spread << " vs "
         << w.spread << ", window_scans " << len << " vs " << w.length << ", windows " << count;
      first_mismatch = os.str();
    }
  }

  int n_;
  int rule_;
  double T_;
  std::vector<AxisBounds> bounds_;
  std::mt19937_64 rng_;
  Instance test_, off_;
  WindowMeter meter_test_, meter_off_;
  BoundChecker check_test_, check_off_;
  CountdownChecker countdown_test_, countdown_off_;
  OvershootChecker overshoot_test_, overshoot_off_;
  std::vector<char> moved_ = std::vector<char>(static_cast<std::size_t>(n_), 0);  // segment changed before this scan
  std::vector<char> still_ = std::vector<char>(static_cast<std::size_t>(n_), 0);  // the segment it left had slope 0
  std::vector<char> was_tracking_test_ = std::vector<char>(static_cast<std::size_t>(n_), 0);
  std::vector<char> was_tracking_off_ = std::vector<char>(static_cast<std::size_t>(n_), 0);
  bool changed_ = true;
  std::vector<double> r_, s_;
  std::int64_t scan_ = 0;
  std::size_t compared_ = 0;
};

// Summary of a lockstep run: windows paired by index (they open on the same
// scans because both instances see the same references and were both
// synchronized before every event).
struct Summary {
  int windows = 0;
  int nonzero_spread = 0;
  std::int64_t max_spread = 0;
  int slower_than_off = 0;    // windows longer than the unsynchronized one
  int not_predicted = 0;      // window length != t_M at its opening
  int slowest_delayed = 0;    // an axis with the largest own time arrived later than its own time
  int energy_higher = 0;      // windows with E above the unsynchronized one
  double e_test = 0, e_off = 0;
  double mean_reduction = 0;  // mean over windows of 1 - E_test/E_off (windows with E_off > 0)
};

inline std::string describe(const Summary& s) {
  std::ostringstream os;
  os << s.windows << " windows, " << s.nonzero_spread << " with spread > 0 (max " << s.max_spread << "), "
     << s.slower_than_off << " longer than unsynchronized, " << s.not_predicted << " not ending at t_M, "
     << s.slowest_delayed << " slowest delayed, " << s.energy_higher << " with higher E; E " << s.e_test << " vs "
     << s.e_off << " (total -" << 100 * (1 - s.e_test / s.e_off) << " %, mean per window -"
     << 100 * s.mean_reduction << " %)";
  return os.str();
}

inline Summary summarize(const LockstepRig& rig) {
  Summary s;
  const auto& wt = rig.windows_test();
  const auto& wo = rig.windows_off();
  EXPECT_EQ(wt.size(), wo.size());
  int counted = 0;
  for (std::size_t k = 0; k < std::min(wt.size(), wo.size()); ++k) {
    const Window& a = wt[k];
    const Window& b = wo[k];
    EXPECT_EQ(a.start, b.start) << "window " << k;
    ++s.windows;
    if (a.spread != 0) ++s.nonzero_spread;
    s.max_spread = std::max(s.max_spread, a.spread);
    if (a.length > b.length) ++s.slower_than_off;
    if (a.length != a.predicted) ++s.not_predicted;
    // The slowest: the largest own time, read from the unsynchronized instance
    // (the same states at the opening; the synchronized one shows t_M on
    // every reduced axis).
    for (std::size_t i = 0; i < b.own.size(); ++i)
      if (b.own[i] == a.predicted && a.arrival[i] != b.own[i]) ++s.slowest_delayed;
    if (a.energy > b.energy * (1 + 1e-9) + 1e-12) ++s.energy_higher;
    s.e_test += a.energy;
    s.e_off += b.energy;
    if (b.energy > 0) {
      s.mean_reduction += 1 - a.energy / b.energy;
      ++counted;
    }
  }
  if (counted) s.mean_reduction /= counted;
  return s;
}

}  // namespace syncplc::motion::synctest
