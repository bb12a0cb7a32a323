// SIM_SERVO: a simulated position-controlled servo drive (the "simulated
// drive" an MC_AXIS can be bound to): a power stage that comes on a set
// number of scans after enable, a position loop modelled as a first-order
// lag (exact for a piecewise-constant target), a fault that a test or an
// operator injects and that stays until a reset edge, and a reference
// switch at a fixed position for homing.
#include <cmath>
#include <memory>

#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {
namespace {

enum : int {
  kSsEnable = 0,
  kSsReset,
  kSsTarget,
  kSsInjectFault,
  kSsPowerOn,
  kSsFault,
  kSsFaultCode,
  kSsPosition,
  kSsVelocity,
  kSsHomeSwitch,
};
enum : int { kSsTau = 0, kSsPowerScans, kSsFaultCodeParam, kSsHomeAt, kSsPosition0 };

class SimServo final : public Block {
 public:
  SimServo(double tau, std::int64_t power_scans, std::uint16_t code, double home_at, double x0) noexcept
      : tau_(tau), power_scans_(power_scans), code_(code), home_at_(home_at), x_(x0) {}

  void execute(ScanContext& ctx) noexcept override {
    const double T = static_cast<double>(ctx.dt_ns) * 1e-9;
    const bool inject = in<bool>(kSsInjectFault);
    const bool reset = in<bool>(kSsReset);
    if (inject && !inject_before_) fault_ = true;
    if (reset && !reset_before_ && !inject) fault_ = false;
    inject_before_ = inject;
    reset_before_ = reset;
    const bool enable = in<bool>(kSsEnable) && !fault_;
    on_scans_ = enable ? on_scans_ + 1 : 0;
    const bool power = enable && on_scans_ > power_scans_;
    const double x_before = x_;
    // Without power the motor stands (held by its brake); with it the
    // position loop follows the target: x' = t + (x - t) e^(-T/tau).
    if (power) x_ = tau_ > 0 ? in<double>(kSsTarget) + (x_ - in<double>(kSsTarget)) * std::exp(-T / tau_)
                             : in<double>(kSsTarget);
    out<bool>(kSsPowerOn, power);
    out<bool>(kSsFault, fault_);
    out<std::uint16_t>(kSsFaultCode, fault_ ? code_ : std::uint16_t{0});
    out<double>(kSsPosition, x_);
    out<double>(kSsVelocity, T > 0 ? (x_ - x_before) / T : 0.0);
    out<bool>(kSsHomeSwitch, x_ >= home_at_);
  }

 private:
  double tau_;
  std::int64_t power_scans_;
  std::uint16_t code_;
  double home_at_;
  double x_;
  std::int64_t on_scans_ = 0;
  bool fault_ = false, inject_before_ = false, reset_before_ = false;
};

std::unique_ptr<Block> make_sim_servo(BlockSetup& s) {
  const double tau = s.param_cell(kSsTau).get<double>();
  const std::int64_t scans = s.param_cell(kSsPowerScans).get<std::int32_t>();
  if (!std::isfinite(tau) || tau < 0) {
    s.error("SIM_SERVO: tau must be finite and >= 0");
    return nullptr;
  }
  return std::make_unique<SimServo>(tau, scans, s.param_cell(kSsFaultCodeParam).get<std::uint16_t>(),
                                    s.param_cell(kSsHomeAt).get<double>(), s.param_cell(kSsPosition0).get<double>());
}

}  // namespace

void register_sim_servo(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "SIM_SERVO";
  t.category = kCategory;
  t.doc =
      "A simulated position-controlled servo drive for an MC_AXIS: the power stage comes on power_scans scans after "
      "enable (and goes off at once without it or in fault); with power the position follows target as a "
      "first-order lag with time constant tau (0: at once), x' = target + (x - target) exp(-T/tau); without it the "
      "motor stands. A rising edge of inject_fault faults the drive (fault_code output = the parameter code) until a rising edge of reset with "
      "inject_fault FALSE. home_switch is TRUE at positions >= home_at.";
  t.reference = "a simulation model (docs/motion/plcopen.md, \"Simulated drive\")";
  t.pins = {
      input("enable", IecType::BOOL).doc("power stage on (MC_AXIS.enable)"),
      input("reset", IecType::BOOL).doc("rising edge: fault reset (MC_AXIS.reset)"),
      input("target", IecType::LREAL).unit("unit").doc("set position (MC_AXIS.drive_position)"),
      input("inject_fault", IecType::BOOL).doc("rising edge: the drive faults"),
      output("power_on", IecType::BOOL).doc("the power stage is on"),
      output("fault", IecType::BOOL).doc("in fault"),
      output("fault_code", IecType::UINT).doc("code while in fault, else 0"),
      output("position", IecType::LREAL).unit("unit").doc("actual position"),
      output("velocity", IecType::LREAL).unit("unit/s").doc("actual velocity over the last scan"),
      output("home_switch", IecType::BOOL).doc("position >= home_at"),
  };
  t.params = {
      parameter("tau", IecType::LREAL).init("0").min(0.0).unit("s").doc("time constant of the position loop"),
      parameter("power_scans", IecType::DINT).init("1").min(0.0).max(1e6).doc("scans from enable to power on"),
      parameter("code", IecType::UINT).init("16#7500").doc("the code reported in fault (CiA 402 603Fh)"),
      parameter("home_at", IecType::LREAL).init("0").unit("unit").doc("where the reference switch turns on"),
      parameter("position0", IecType::LREAL).init("0").unit("unit").doc("position at start"),
  };
  t.create = make_sim_servo;
  r.add(std::move(t));
}

}  // namespace syncplc::plcopen
