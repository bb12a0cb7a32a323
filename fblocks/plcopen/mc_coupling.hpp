// What MC_GearIn and MC_CamIn share (PLCopen Part 1 v2.0 §4.4, §4.2): the
// links Master and Slave (two MC_AXIS instances), the master's value for the
// coming scan, the slave's Synchronized command fed every scan
// (AxisMachine::feed) and the outputs of §2.4.1. The block computes the
// slave's set values of the next scan from the master's; the slave checks
// each against its limits (SyncLimit, axis_sync.cpp).
#pragma once

#include <cmath>
#include <cstdint>

#include "fblocks/plcopen/axis_block.hpp"
#include "fblocks/plcopen/mc_block.hpp"
#include "runtime/core/block.hpp"

namespace syncplc::plcopen {

// MC_SOURCE (§4.4): which master value the slave follows.
enum class MasterSource : std::int16_t { SetValue = 0, ActualValue = 1 };

// The master's position (continuous, also on a modulo master), velocity and
// acceleration as the slave's next scan will have them.
struct MasterSample {
  double x = 0, v = 0, a = 0;
};

// The outputs of a coupling block: Busy, Active, CommandAborted, Error are
// exclusive as in §2.4.1; in_sync is InGear / InSync.
struct CouplingOutputs {
  bool busy = false, active = false, aborted = false, error = false, in_sync = false;
  std::uint16_t error_id = 0;
};

class CouplingBlock : public Block {
 public:
  // Link 0: Master, 1: Slave.
  void link(int link, std::uint32_t, Block& target) noexcept override {
    auto* axis = dynamic_cast<AxisBlock*>(&target);
    AxisBlock*& slot = link == 0 ? master_ : slave_;
    if (axis != slot) {
      // An axis re-created by an online change: the coupling went with it.
      if (slot && running_) lost_ = true;
      slot = axis;
    }
  }

 protected:
  // Once per scan with Execute: the edge submits, then the coupling is
  // followed and fed; the ended outputs show per §2.4.1.
  void run(ScanContext& ctx, bool execute) noexcept {
    const bool rising = execute && !execute_before_;
    execute_before_ = execute;
    if (rising) {
      out_ = {};
      ended_ = false;
      running_ = started_ = lost_ = false;
      id_ = 0;
      begin(ctx);
    } else if (running_) {
      follow();
    }
    if (ended_) {
      if (!execute && shown_) {
        out_ = {};
        ended_ = false;
      } else {
        shown_ = true;
      }
    }
  }

  // The inputs at the edge: None, or why the coupling is refused.
  virtual AxisError sample_inputs() noexcept = 0;
  // The coupling starts (the slave's command became Active): the master and
  // slave values at this scan are its origin.
  virtual void on_start(const MasterSample& master_now) noexcept = 0;
  // The slave's sample for the next scan from the master's; done hands the
  // slave over to the command buffered behind (only when one waits).
  virtual void next_sample(const MasterSample& m, motion::FilterState* next, bool* done) noexcept = 0;

  void end(bool aborted, AxisError e) noexcept {
    running_ = false;
    out_ = {};
    out_.aborted = aborted;
    out_.error = !aborted;
    out_.error_id = static_cast<std::uint16_t>(e);
    ended_ = true;
    shown_ = false;
    id_ = 0;
  }

  AxisBlock* master_ = nullptr;
  AxisBlock* slave_ = nullptr;
  MasterSource source_ = MasterSource::SetValue;
  BufferMode buffer_ = BufferMode::Aborting;
  CouplingOutputs out_{};
  double T_ = 0.001;
  std::int64_t synced_scans_ = 0;  // scans the slave's set values have been the coupling's

 private:
  static bool master_failed(const AxisMachine& m) noexcept {
    return m.state() == AxisState::Disabled || m.state() == AxisState::ErrorStop;
  }

  void begin(ScanContext& ctx) noexcept {
    if (!master_ || !slave_) return end(false, AxisError::Disabled);
    if (master_ == slave_) return end(false, AxisError::BadSyncInput);
    if (const AxisError e = sample_inputs(); e != AxisError::None) return end(false, e);
    if (master_failed(master_->machine())) return end(false, AxisError::MasterFailed);
    Command c;
    c.kind = CommandKind::Synchronized;
    c.buffer = buffer_;
    AxisError e = AxisError::None;
    id_ = slave_->submit(c, ctx.block, &e);
    if (!id_) return end(false, e);
    running_ = true;
    have_actual_ = false;
    follow();
  }

  void follow() noexcept {
    if (lost_) return end(true, AxisError::None);
    const CommandReport r = slave_->machine().report(id_);
    switch (r.status) {
      case CommandStatus::Buffered:
        out_.busy = true;
        out_.active = false;
        return;
      case CommandStatus::Active: break;
      case CommandStatus::Error: return end(false, r.error);
      default:
        // Aborted by another command, MC_Power off, or handed over to the
        // buffered one at a cam's end (Done): the next command has the slave.
        return end(true, AxisError::None);
    }
    const AxisMachine& m = master_->machine();
    // The master failed: the slave is let go and brakes on its own
    // (not fed, AxisMachine::advance), this command ends with Error.
    if (master_failed(m)) return end(false, AxisError::MasterFailed);
    const MasterSample now = master_now(m);
    if (!started_) {
      started_ = true;
      synced_scans_ = 0;
      on_start(now);
    } else {
      ++synced_scans_;
    }
    MasterSample next = now;
    next.x = now.x + T_ * now.v + 0.5 * T_ * T_ * now.a;
    next.v = now.v + T_ * now.a;
    motion::FilterState s{};
    bool done = false;
    next_sample(next, &s, &done);
    const AxisMachine& sl = slave_->machine();
    const double a = (s.v - sl.set_velocity()) / T_;
    slave_->machine().feed(id_, s, a, -1, done && sl.has_buffered());
    out_.busy = out_.active = true;
  }

  // The set values are what the master's profile makes exactly (its
  // acceleration over the coming scan is known); actual values are
  // extrapolated with the actual velocity and, on a modulo master,
  // unwrapped by the shortest way from the scan before.
  MasterSample master_now(const AxisMachine& m) noexcept {
    if (source_ == MasterSource::SetValue) return {m.set_position(), m.set_velocity(), m.set_acceleration()};
    const double p = m.actual_position(), mod = m.limits().modulo;
    if (!have_actual_ || mod <= 0) {
      actual_x_ = p;
    } else {
      double d = p - actual_wrapped_;
      d -= mod * std::round(d / mod);
      actual_x_ += d;
    }
    have_actual_ = true;
    actual_wrapped_ = p;
    return {actual_x_, m.actual_velocity(), 0};
  }

  CommandId id_ = 0;
  bool execute_before_ = false, running_ = false, started_ = false, lost_ = false, ended_ = false, shown_ = false;
  bool have_actual_ = false;
  double actual_x_ = 0, actual_wrapped_ = 0;
};

// MC_SOURCE, BufferMode and Jerk as the coupling blocks take them at the edge.
inline AxisError coupling_common(std::int16_t source, std::int16_t buffer, MasterSource* src, BufferMode* bm) noexcept {
  if (source != 0 && source != 1) return AxisError::BadSyncInput;
  if (buffer < 0 || buffer > 5) return AxisError::BadBufferMode;
  *src = static_cast<MasterSource>(source);
  *bm = static_cast<BufferMode>(buffer);
  return AxisError::None;
}

}  // namespace syncplc::plcopen
