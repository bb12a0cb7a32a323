// The administrative blocks of PLCopen Part 1 v2.0: MC_Power (§3.1),
// MC_Reset (§3.11), MC_ReadStatus (§3.15), MC_ReadActualPosition (§3.13),
// MC_ReadActualVelocity (§3.14), MC_ReadAxisError (§3.16), MC_SetPosition
// (§3.12), MC_ReadParameter (§3.19) and MC_WriteParameter (§3.20). None
// of them changes the state diagram except MC_Power and MC_Reset.
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "fblocks/plcopen/mc_block.hpp"
#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {
namespace {

// Outputs of the Execute blocks that end at once or after a wait of their
// own (MC_Reset, MC_SetPosition, MC_WriteParameter), by §2.4.1's rules.
class EdgeOutputs {
 public:
  enum class Outcome : std::uint8_t { Busy, Done, Error };
  // start() at the rising edge, poll() while Busy; each returns the outcome
  // and sets *e for Error.
  template <class Start, class Poll>
  void update(bool execute, Start&& start, Poll&& poll) noexcept {
    const bool rising = execute && !before_;
    before_ = execute;
    AxisError e = AxisError::None;
    if (rising) {
      busy_ = done_ = error_ = ended_ = false;
      error_id_ = 0;
      take(start(&e), e);
    } else if (busy_) {
      take(poll(&e), e);
    }
    if (ended_) {
      if (!execute && shown_) {
        done_ = error_ = ended_ = false;
        error_id_ = 0;
      } else {
        shown_ = true;
      }
    }
  }
  bool busy() const noexcept { return busy_; }
  bool done() const noexcept { return done_; }
  bool error() const noexcept { return error_; }
  std::uint16_t error_id() const noexcept { return error_id_; }

 private:
  void take(Outcome o, AxisError e) noexcept {
    busy_ = o == Outcome::Busy;
    if (o == Outcome::Busy) return;
    done_ = o == Outcome::Done;
    error_ = o == Outcome::Error;
    error_id_ = static_cast<std::uint16_t>(e);
    ended_ = true;
    shown_ = false;
  }
  bool before_ = false, busy_ = false, done_ = false, error_ = false, ended_ = false, shown_ = false;
  std::uint16_t error_id_ = 0;
};
using Outcome = EdgeOutputs::Outcome;

// ---- MC_Power --------------------------------------------------------------

enum : int { kPwEnable = 0, kPwStatus, kPwValid, kPwError, kPwErrorId };

class PowerBlock final : public McBlock {
 public:
  void execute(ScanContext&) noexcept override {
    const bool enable = in<bool>(kPwEnable);
    bool status = false, error = false;
    std::uint16_t id = 0;
    if (axis_) {
      AxisMachine& m = axis_->machine();
      m.request_power(enable);
      status = m.power_on();
      // §3.1: the power stage failing while enabled is this block's error too.
      if (enable && m.state() == AxisState::ErrorStop &&
          (m.axis_error() == AxisError::PowerLost || m.axis_error() == AxisError::DriveFault)) {
        error = true;
        id = static_cast<std::uint16_t>(m.axis_error());
      }
    }
    out<bool>(kPwStatus, status);
    out<bool>(kPwValid, axis_ != nullptr && enable && !error);
    out<bool>(kPwError, error);
    out<std::uint16_t>(kPwErrorId, id);
  }
};

// ---- MC_Reset ----------------------------------------------------------------

enum : int { kRsExecute = 0, kRsDone, kRsBusy, kRsError, kRsErrorId };

class ResetBlock final : public McBlock {
 public:
  void execute(ScanContext&) noexcept override {
    AxisMachine* m = axis_ ? &axis_->machine() : nullptr;
    auto left = [&](AxisError* e) {
      if (!m) {
        *e = AxisError::Disabled;
        return Outcome::Error;
      }
      return m->state() == AxisState::ErrorStop ? Outcome::Busy : Outcome::Done;
    };
    edge_.update(
        in<bool>(kRsExecute),
        [&](AxisError* e) {
          if (!m) return left(e);
          // §3.11: a reset outside ErrorStop has nothing to do.
          if (const AxisError r = m->reset(); r != AxisError::None) {
            *e = r;
            return Outcome::Error;
          }
          return left(e);
        },
        left);
    out<bool>(kRsDone, edge_.done());
    out<bool>(kRsBusy, edge_.busy());
    out<bool>(kRsError, edge_.error());
    out<std::uint16_t>(kRsErrorId, edge_.error_id());
  }

 private:
  EdgeOutputs edge_;
};

// ---- MC_SetPosition -------------------------------------------------------------

enum : int { kSpExecute = 0, kSpPosition, kSpRelative, kSpDone, kSpBusy, kSpError, kSpErrorId };

class SetPositionBlock final : public McBlock {
 public:
  void execute(ScanContext&) noexcept override {
    auto start = [&](AxisError* e) {
      *e = axis_ ? axis_->machine().set_position(in<double>(kSpPosition), in<bool>(kSpRelative)) : AxisError::Disabled;
      return *e == AxisError::None ? Outcome::Done : Outcome::Error;
    };
    edge_.update(in<bool>(kSpExecute), start, [](AxisError*) { return Outcome::Done; });
    out<bool>(kSpDone, edge_.done());
    out<bool>(kSpBusy, edge_.busy());
    out<bool>(kSpError, edge_.error());
    out<std::uint16_t>(kSpErrorId, edge_.error_id());
  }

 private:
  EdgeOutputs edge_;
};

// ---- MC_WriteParameter ----------------------------------------------------------

enum : int { kWpExecute = 0, kWpNumber, kWpValue, kWpDone, kWpBusy, kWpError, kWpErrorId };

class WriteParameterBlock final : public McBlock {
 public:
  void execute(ScanContext&) noexcept override {
    auto start = [&](AxisError* e) {
      *e = axis_ ? axis_->machine().write_parameter(in<std::int16_t>(kWpNumber), in<double>(kWpValue))
                 : AxisError::Disabled;
      return *e == AxisError::None ? Outcome::Done : Outcome::Error;
    };
    edge_.update(in<bool>(kWpExecute), start, [](AxisError*) { return Outcome::Done; });
    out<bool>(kWpDone, edge_.done());
    out<bool>(kWpBusy, edge_.busy());
    out<bool>(kWpError, edge_.error());
    out<std::uint16_t>(kWpErrorId, edge_.error_id());
  }

 private:
  EdgeOutputs edge_;
};

// ---- the Enable blocks: MC_Read* -------------------------------------------------
// §2.4.1/§2.2.3: while Enable is TRUE, Busy; Valid when the outputs are
// good; a recoverable error (stale feedback) drops Valid, sets Error, and
// Busy stays. Enable FALSE clears every output.

struct ReadResult {
  bool ok = true;
  AxisError error = AxisError::None;
};

// One reader: the common pins first (Enable; Valid, Busy, Error, ErrorID),
// then its own outputs, which `read` writes.
class ReadBlock final : public McBlock {
 public:
  using Reader = void (*)(const AxisMachine& m, Block& b, ReadResult* r, bool enable);
  explicit ReadBlock(Reader read) noexcept : read_(read) {}

  void execute(ScanContext&) noexcept override {
    const bool enable = in<bool>(0);
    ReadResult r;
    if (!axis_) r = {false, AxisError::Disabled};
    else read_(axis_->machine(), *this, &r, enable);
    out<bool>(1, enable && r.ok);
    out<bool>(2, enable);
    out<bool>(3, enable && !r.ok);
    out<std::uint16_t>(4, enable && !r.ok ? static_cast<std::uint16_t>(r.error) : 0);
  }

 private:
  Reader read_;
};

void read_status(const AxisMachine& m, Block& b, ReadResult*, bool enable) {
  const AxisState s = m.state();
  const AxisState order[] = {AxisState::ErrorStop,      AxisState::Disabled,         AxisState::Stopping,
                             AxisState::Homing,         AxisState::Standstill,       AxisState::DiscreteMotion,
                             AxisState::ContinuousMotion, AxisState::SynchronizedMotion};
  for (int i = 0; i < 8; ++i) b.out<bool>(5 + i, enable && s == order[i]);
}

void read_position(const AxisMachine& m, Block& b, ReadResult* r, bool enable) {
  // Never stale data as if fresh: a position from a bad exchange is not Valid.
  if (!m.feedback_valid()) *r = {false, AxisError::FeedbackLost};
  b.out<double>(5, enable && r->ok ? m.actual_position() : 0.0);
}

void read_velocity(const AxisMachine& m, Block& b, ReadResult* r, bool enable) {
  if (!m.feedback_valid()) *r = {false, AxisError::FeedbackLost};
  b.out<double>(5, enable && r->ok ? m.actual_velocity() : 0.0);
}

void read_axis_error(const AxisMachine& m, Block& b, ReadResult*, bool enable) {
  b.out<std::uint16_t>(5, enable ? static_cast<std::uint16_t>(m.axis_error()) : 0);
  b.out<std::uint16_t>(6, enable ? m.drive_fault_code() : 0);
}

void read_parameter(const AxisMachine& m, Block& b, ReadResult* r, bool enable) {
  double v = 0;
  if (const AxisError e = m.read_parameter(b.in<std::int16_t>(5), &v); e != AxisError::None) *r = {false, e};
  b.out<double>(6, enable && r->ok ? v : 0.0);
}

std::vector<PinDecl> enable_pins() {
  return {
      input("Enable", IecType::BOOL).doc("TRUE: the outputs follow the axis every scan"),
      output("Valid", IecType::BOOL).doc("the outputs are valid"),
      output("Busy", IecType::BOOL).doc("Enable is TRUE"),
      output("Error", IecType::BOOL).doc("the outputs cannot be read now (ErrorID says why)"),
      output("ErrorID", IecType::WORD).doc("docs/motion/plcopen.md, \"Error IDs\""),
  };
}

std::vector<PinDecl> execute_pins(std::vector<PinDecl> inputs) {
  std::vector<PinDecl> pins = {input("Execute", IecType::BOOL).doc("rising edge: the block acts, with the inputs sampled now")};
  for (auto& p : inputs) pins.push_back(std::move(p));
  pins.push_back(output("Done", IecType::BOOL).doc("done"));
  pins.push_back(output("Busy", IecType::BOOL).doc("not finished yet"));
  pins.push_back(output("Error", IecType::BOOL).doc("refused or failed"));
  pins.push_back(output("ErrorID", IecType::WORD).doc("docs/motion/plcopen.md, \"Error IDs\""));
  return pins;
}

void add(BlockRegistry& r, const char* name, const char* section, const char* doc, std::vector<PinDecl> pins,
         BlockFactory create) {
  BlockTypeInfo t;
  t.name = name;
  t.category = kCategory;
  t.doc = doc;
  t.reference = std::string("PLCopen Motion Control Part 1 v2.0, ") + section + " and 2.4.1";
  t.pins = std::move(pins);
  t.links = {axis_link()};
  // PLCopen 3.1: one MC_Power per axis (two would fight over its power stage).
  if (std::string(name) == "MC_Power") t.links[0].exclusive = "one MC_Power per axis, PLCopen Part 1 section 3.1";
  t.create = std::move(create);
  r.add(std::move(t));
}

void add_reader(BlockRegistry& r, const char* name, const char* section, const char* doc,
                std::vector<PinDecl> own, ReadBlock::Reader read) {
  std::vector<PinDecl> pins = enable_pins();
  for (auto& p : own) pins.push_back(std::move(p));
  add(r, name, section, doc, std::move(pins),
      [read](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<ReadBlock>(read); });
}

}  // namespace

void register_admin_blocks(BlockRegistry& r) {
  add(r, "MC_Power", "3.1",
      "Switches the axis's power stage with Enable (level): Disabled -> Standstill once the drive reports it on; "
      "Enable FALSE -> Disabled from any state but ErrorStop, every command of the axis CommandAborted. Status: "
      "the power stage is on. Error: the power stage failed or the drive faulted while Enable is TRUE.",
      {
          input("Enable", IecType::BOOL).doc("TRUE: power stage on"),
          output("Status", IecType::BOOL).doc("the power stage is on"),
          output("Valid", IecType::BOOL).doc("Enable is TRUE and no error"),
          output("Error", IecType::BOOL).doc("the power stage failed or the drive faulted while enabled"),
          output("ErrorID", IecType::WORD).doc("the axis error"),
      },
      [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<PowerBlock>(); });
  add(r, "MC_Reset", "3.11",
      "Leaves ErrorStop at Execute's rising edge: to Standstill when the power stage is on and MC_Power asks for "
      "it, else Disabled. A drive fault is acknowledged first (the axis's reset output); Busy until the drive "
      "leaves its fault; refused while the axis still brakes. Outside ErrorStop: Done, nothing changes.",
      execute_pins({}),
      [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<ResetBlock>(); });
  add(r, "MC_SetPosition", "3.12",
      "In Standstill or Disabled, the axis's position becomes Position (Relative: moves by it) without motion.",
      execute_pins({input("Position", IecType::LREAL).doc("new position, user units"),
                    input("Relative", IecType::BOOL).doc("TRUE: Position is added to the position")}),
      [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<SetPositionBlock>(); });
  add(r, "MC_WriteParameter", "3.20",
      "Writes the axis parameter ParameterNumber (docs/motion/plcopen.md, \"Parameters\"; BOOL ones as 0/1).",
      execute_pins({input("ParameterNumber", IecType::INT).doc("the parameter's number"),
                    input("Value", IecType::LREAL).doc("its new value")}),
      [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<WriteParameterBlock>(); });
  add_reader(r, "MC_ReadStatus", "3.15", "The axis's state in the state diagram, one output per state.",
             {output("ErrorStop", IecType::BOOL), output("Disabled", IecType::BOOL), output("Stopping", IecType::BOOL),
              output("Homing", IecType::BOOL), output("Standstill", IecType::BOOL),
              output("DiscreteMotion", IecType::BOOL), output("ContinuousMotion", IecType::BOOL),
              output("SynchronizedMotion", IecType::BOOL)},
             read_status);
  add_reader(r, "MC_ReadActualPosition", "3.13",
             "The actual position, user units (wrapped on a modulo axis); not Valid while the drive's feedback is "
             "stale.",
             {output("Position", IecType::LREAL).doc("actual position, user units")}, read_position);
  add_reader(r, "MC_ReadActualVelocity", "3.14",
             "The actual velocity, user units/s; not Valid while the drive's feedback is stale.",
             {output("Velocity", IecType::LREAL).doc("actual velocity, user units/s")}, read_velocity);
  add_reader(r, "MC_ReadAxisError", "3.16", "The axis error (0 none) and the drive's fault code.",
             {output("AxisErrorID", IecType::WORD).doc("the axis error (docs/motion/plcopen.md, \"Error IDs\")"),
              output("DriveErrorID", IecType::WORD).doc("the drive's error code seen at its fault")},
             read_axis_error);
  add_reader(r, "MC_ReadParameter", "3.19",
             "Reads the axis parameter ParameterNumber every scan (docs/motion/plcopen.md, \"Parameters\"; BOOL ones "
             "as 0/1).",
             {input("ParameterNumber", IecType::INT).doc("the parameter's number"),
              output("Value", IecType::LREAL).doc("its value")},
             read_parameter);
}

}  // namespace syncplc::plcopen
