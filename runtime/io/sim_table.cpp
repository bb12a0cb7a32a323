#include "runtime/io/sim_table.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "runtime/io/driver_config.hpp"

namespace syncplc {
namespace {

// Paper 000 §5.1: axes 1-3 measured; axis 4 is axis 2's model (it gets the disturbance).
const std::vector<double> kPaperTau = {0.055, 0.056, 0.040, 0.056};
const std::vector<double> kPaperGain = {35.6206, 36.3872, 52.2836, 36.3872};

}  // namespace

SimTableDriver::SimTableDriver(SimTableConfig cfg) : cfg_(std::move(cfg)), rng_(cfg_.seed) {
  const std::uint32_t n = static_cast<std::uint32_t>(cfg_.axes.size());
  channels_ = {
      {"cmd", PinDir::Out, IecType::LREAL, n, "PWM", "drive commands"},
      {"pos", PinDir::In, IecType::LREAL, n, "rad", "measured positions"},
      {"vel", PinDir::In, IecType::LREAL, n, "rad/s", "velocities reported by the drives"},
      {"applied", PinDir::In, IecType::LREAL, n, "PWM", "motor input last period: saturated command + disturbance + load"},
      {"load", PinDir::Out, IecType::LREAL, n, "PWM", "load set by the program, added to the motor input beyond the drive's limit"},
  };
  bound_.assign(channels_.size(), nullptr);
  for (std::size_t i = 0; i < n; ++i) {
    plants_.emplace_back(cfg_.axes[i]);
    plants_.back().set_state(i < cfg_.position0.size() ? cfg_.position0[i] : 0.0, 0.0);
    // The intervals met every scan: the period, and the two pieces the deferred actuation cuts it into.
    plants_.back().prepare(cfg_.period_ns);
    if (cfg_.actuation_delay_ns > 0) {
      plants_.back().prepare(cfg_.actuation_delay_ns);
      plants_.back().prepare(cfg_.period_ns - cfg_.actuation_delay_ns);
    }
  }
  active_.assign(n, 0.0);
  pending_.assign(n, 0.0);
  applied_.assign(n, 0.0);
  last_cmd_.assign(n, 0.0);
  last_load_.assign(n, 0.0);
  safe_cmd_.assign(n, 0.0);
  for (const auto& d : cfg_.disturbances) {
    edges_.push_back(d.from_ns);
    edges_.push_back(d.to_ns);
  }
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
  if (cfg_.encoder_lines > 0) quantum_ = 2 * std::numbers::pi / (4.0 * cfg_.encoder_lines);
}

double SimTableDriver::disturbance(std::size_t axis, std::int64_t t) const noexcept {
  double d = 0;
  for (const auto& x : cfg_.disturbances)
    if (x.axis == axis && t >= x.from_ns && t < x.to_ns) d += x.value;
  return d;
}

double SimTableDriver::measure(double theta) noexcept {
  if (cfg_.noise > 0) theta += cfg_.noise * rng_.gaussian();
  if (quantum_ > 0) theta = std::floor(theta / quantum_) * quantum_;  // the position counter truncates
  return theta;
}

void SimTableDriver::advance_to(std::int64_t t) noexcept {
  const std::size_t n = plants_.size();
  std::fill(applied_.begin(), applied_.end(), 0.0);
  const double span = static_cast<double>(t - t_);
  while (t_ < t) {
    if (have_pending_ && switch_at_ <= t_) {
      active_.swap(pending_);
      have_pending_ = false;
    }
    std::int64_t next = t;
    if (have_pending_ && switch_at_ < next) next = switch_at_;
    auto e = std::upper_bound(edges_.begin(), edges_.end(), t_);
    if (e != edges_.end() && *e < next) next = *e;
    for (std::size_t i = 0; i < n; ++i) {
      double u = active_[i] + disturbance(i, t_);
      plants_[i].advance(u, next - t_);
      applied_[i] += u * static_cast<double>(next - t_) / span;  // mean input over the period
    }
    t_ = next;
  }
}

bool SimTableDriver::open(std::string*) {
  safe_.reset();
  safe_ready_.store(false, std::memory_order_release);
  safe_taken_ = false;
  return true;
}

void SimTableDriver::latch_inputs(const ScanContext& ctx) noexcept {
  if (!started_) {
    t_ = ctx.now_ns;
    started_ = true;
  } else if (ctx.now_ns > t_) {
    advance_to(ctx.now_ns);
  }
  if (!safe_taken_ && safe_ready_.load(std::memory_order_acquire)) {  // the safe commands act from now on
    // The load is the machine's, not the drive's: it stays as the program last set it.
    for (std::size_t i = 0; i < active_.size(); ++i) {
      const double u = std::isfinite(safe_cmd_[i]) ? safe_cmd_[i] : 0.0;
      active_[i] = std::clamp(u, -cfg_.saturation, cfg_.saturation) + last_load_[i];
    }
    have_pending_ = false;
    safe_taken_ = true;
  }
  const std::size_t n = plants_.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (Cell* c = bound_[kPos]) c[i].set<double>(measure(plants_[i].position()));
    if (Cell* c = bound_[kVel]) c[i].set<double>(plants_[i].velocity());
    if (Cell* c = bound_[kApplied]) c[i].set<double>(applied_[i]);
  }
}

void SimTableDriver::write_outputs(const ScanContext& ctx) noexcept {
  Cell* c = bound_[kCmd];
  Cell* load = bound_.size() > kLoad ? bound_[kLoad] : nullptr;
  if (!c || !safe_.begin_write()) return;
  if (have_pending_) {  // two writes without a latch between them: the older one never acted
    active_.swap(pending_);
  }
  for (std::size_t i = 0; i < plants_.size(); ++i) {
    double u = c[i].get<double>();
    last_cmd_[i] = u;
    if (!std::isfinite(u)) {  // a drive refuses a non-number: it keeps its output at zero
      ++bad_commands_;
      u = 0;
    }
    double l = load ? load[i].get<double>() : 0.0;
    if (!std::isfinite(l)) l = 0;  // as a refused command: no load rather than a non-number in the plant
    last_load_[i] = l;
    pending_[i] = std::clamp(u, -cfg_.saturation, cfg_.saturation) + l;
  }
  switch_at_ = ctx.now_ns + cfg_.actuation_delay_ns;
  have_pending_ = true;
  safe_.end_write();
}

bool SimTableDriver::write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept {
  if (safe_ready_.load(std::memory_order_acquire)) return true;  // already in the safe state
  if (!safe_.engage()) return false;
  // After engage() the scan thread no longer writes last_cmd_: the commands
  // without a safe value keep their last value.
  std::copy(last_cmd_.begin(), last_cmd_.end(), safe_cmd_.begin());  // sized at construction: no allocation
  for (std::size_t i = 0; i < n; ++i)
    if (outputs[i].channel == kCmd && outputs[i].element < safe_cmd_.size())
      safe_cmd_[outputs[i].element] = outputs[i].value.get<double>();
  safe_ready_.store(true, std::memory_order_release);
  return true;
}

bool SimTableDriver::read_output(int channel, Cell* values) const {
  if (channel != kCmd) return false;
  const bool safe = safe_ready_.load(std::memory_order_acquire);
  const auto& cmd = safe ? safe_cmd_ : last_cmd_;
  for (std::size_t i = 0; i < cmd.size(); ++i) values[i].set<double>(cmd[i]);
  return true;
}

DriverTypeInfo sim_table_driver_type() {
  DriverTypeInfo t;
  t.name = "sim_table";
  t.doc =
      "Simulated multi-axis table: each axis is the DC motor of paper 000 eq. (25), P(s) = k/(s(tau s + 1)), "
      "discretised exactly (zero-order hold). Keys: axes (default 4), tau (s) and gain ((rad/s)/PWM), one value "
      "or one per axis (default: the paper's 0.055/0.056/0.040/0.056 s and 35.6206/36.3872/52.2836/36.3872), "
      "paper_axis (1..4, default 1: the paper's axis whose values the first axis takes by default, the next ones "
      "following), "
      "saturation (PWM, default 1), position0 (rad), encoder_lines (lines per revolution, counted 4x; 0 = ideal), "
      "noise (rad, standard deviation), actuation_delay (duration, less than the period), disturbance (list of "
      "{axis, from, to, value} in PWM added to the motor input). Channels cmd (out), pos, vel, applied (in), "
      "load (out: PWM added to the motor input beyond the drive's limit, from the same instant as cmd), each "
      "ARRAY[1..axes] OF LREAL.";
  t.create = [](const ConfigNode& node, DriverSetup& setup) -> std::unique_ptr<IoDriver> {
    DriverConfig c(node, setup, "sim_table",
                   {"axes", "paper_axis", "tau", "gain", "saturation", "position0", "encoder_lines", "noise",
                    "actuation_delay", "disturbance"});
    SimTableConfig cfg;
    cfg.period_ns = setup.task_period_ns();
    cfg.seed = setup.seed();
    const auto n = static_cast<std::size_t>(c.integer("axes", 4, 1, 256));
    // A node of a distributed table simulates one axis of the machine: its
    // axis 1 is the paper's axis `paper_axis`, and any further ones follow.
    const auto first = static_cast<std::size_t>(c.integer("paper_axis", 1, 1, 4)) - 1;
    std::vector<double> tau_def(n), gain_def(n);
    for (std::size_t i = 0; i < n; ++i) {
      tau_def[i] = kPaperTau[std::min(first + i, kPaperTau.size() - 1)];
      gain_def[i] = kPaperGain[std::min(first + i, kPaperGain.size() - 1)];
    }
    auto tau = c.numbers("tau", "s", n, tau_def, 1e-6, 1e3);
    auto gain = c.numbers("gain", "(rad/s)/PWM", n, gain_def, 1e-9, 1e9);
    for (std::size_t i = 0; i < n; ++i) cfg.axes.push_back(AxisModel{tau[i], gain[i]});
    cfg.saturation = c.number("saturation", "PWM", 1.0, 1e-9, 1e9);
    cfg.position0 = c.numbers("position0", "rad", n, {0.0});
    cfg.encoder_lines = static_cast<std::uint32_t>(c.integer("encoder_lines", 0, 0, 1'000'000'000));
    cfg.noise = c.number("noise", "rad", 0.0, 0.0, 1e3);
    cfg.actuation_delay_ns = c.duration_ns("actuation_delay", 0, 0, cfg.period_ns - 1);
    if (const ConfigNode* d = c.node("disturbance")) {
      if (!d->is_list()) c.error(d->loc, "disturbance: expected a list of {axis, from, to, value}");
      else
        for (const auto& item : d->items) {
          if (!item.is_map() || !item.find("axis") || !item.find("from") || !item.find("to") || !item.find("value")) {
            c.error(item.loc, "a disturbance is {axis: 1.." + std::to_string(n) + ", from: 2s, to: 4s, value: 0.05}");
            continue;
          }
          Disturbance x;
          double axis = c.number_at(*item.find("axis"), "disturbance axis", "", 1, static_cast<double>(n));
          x.from_ns = c.duration_at(*item.find("from"), "disturbance from");
          x.to_ns = c.duration_at(*item.find("to"), "disturbance to");
          x.value = c.number_at(*item.find("value"), "disturbance value", "PWM");
          if (!std::isnan(axis) && axis != std::floor(axis)) c.error(item.find("axis")->loc, "disturbance axis must be an integer");
          if (x.from_ns >= 0 && x.to_ns >= 0 && x.to_ns <= x.from_ns)
            c.error(item.find("to")->loc, "disturbance 'to' must be later than 'from'");
          for (const auto& [k, v] : item.map)
            if (k != "axis" && k != "from" && k != "to" && k != "value")
              c.error(v.loc, "unknown key '" + k + "' in a disturbance (axis, from, to, value)");
          if (std::isnan(axis)) continue;
          x.axis = static_cast<std::uint32_t>(axis) - 1;
          cfg.disturbances.push_back(x);
        }
    }
    if (!c.ok()) return nullptr;
    return std::make_unique<SimTableDriver>(std::move(cfg));
  };
  return t;
}

}  // namespace syncplc
