// MC_GroupMoveAbsolute: n axes moved to their positions so that all arrive
// on the same scan, each within its own limits, re-targetable in flight
// (ContinuousUpdate), with the scans to the common arrival as an output.
// Paper 004's synchronizer (Section III, eqs. 23-34, with the corrections of
// docs/motion/transient-sync.md) runs the n filters (TransientSyncCore, the
// algorithm of TRANSIENT_SYNC); each axis takes its filter's samples as a
// GroupMove command (axis_machine.hpp, feed). Named after the group
// vocabulary of PLCopen Part 4; the axes are the link list `Axes`, not an
// AXES_GROUP_REF (docs/motion/plcopen.md, "The group move").
#include <cmath>
#include <memory>
#include <vector>

#include "fblocks/motion/transient_sync_core.hpp"
#include "fblocks/plcopen/mc_block.hpp"
#include "fblocks/plcopen/plcopen.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::plcopen {
namespace {

enum : int { kGmExecute = 0, kGmUpdate, kGmPosition, kGmDone, kGmBusy, kGmActive, kGmAborted, kGmError, kGmErrorId, kGmRemaining };

class GroupMove final : public Block {
 public:
  GroupMove(std::uint32_t n, double T)
      : n_(n), core_(n, motion::SyncRule::Unified, T, false), axes_(n, nullptr), ids_(n, 0), r_(n, 0.0),
        r_dot_(n, 0.0), v_min_(n), v_max_(n), a_min_(n), a_max_(n) {}

  void link(int, std::uint32_t element, Block& target) noexcept override {
    if (element >= n_) return;
    auto* axis = dynamic_cast<AxisBlock*>(&target);
    if (axis != axes_[element]) {
      // An axis re-created by an online change: its command went with it.
      if (axes_[element] && running_) lost_ = true;
      axes_[element] = axis;
    }
  }

  void execute(ScanContext& ctx) noexcept override {
    const bool execute = in<bool>(kGmExecute);
    const bool rising = execute && !execute_before_;
    execute_before_ = execute;
    if (rising) {
      out_ = {};
      ended_ = false;
      begin(ctx);
    } else if (running_) {
      follow();
    }
    if (ended_) {  // §2.4.1: shown once with Execute low, then cleared
      if (!execute && shown_) {
        out_ = {};
        ended_ = false;
      } else {
        shown_ = true;
      }
    }
    out<bool>(kGmDone, out_.done);
    out<bool>(kGmBusy, out_.busy);
    out<bool>(kGmActive, out_.active);
    out<bool>(kGmAborted, out_.aborted);
    out<bool>(kGmError, out_.error);
    out<std::uint16_t>(kGmErrorId, out_.error_id);
    out<std::int64_t>(kGmRemaining, running_ ? remaining_ : (out_.done ? 0 : -1));
  }

 private:
  void end(bool done, bool aborted, AxisError e) noexcept {
    running_ = false;
    out_ = {};
    out_.done = done;
    out_.aborted = aborted;
    out_.error = !done && !aborted;
    out_.error_id = static_cast<std::uint16_t>(e);
    ended_ = true;
    shown_ = false;
  }

  // The filter bounds of axis i from its *Appl limits and the side its
  // target lies on (speeding up with Acceleration, slowing down with
  // Deceleration, as a single axis's discrete move).
  void bounds(std::uint32_t i) noexcept {
    const AxisMachine& m = axes_[i]->machine();
    const AxisLimits& l = m.limits();
    const bool up = r_[i] >= core_.state(i).x;
    v_min_[i] = -l.v_max;
    v_max_[i] = l.v_max;
    a_max_[i] = up ? l.a_max : l.d_max;
    a_min_[i] = up ? -l.d_max : -l.a_max;
  }

  void begin(ScanContext& ctx) noexcept {
    running_ = false;
    lost_ = false;
    update_ = in<bool>(kGmUpdate);
    for (std::uint32_t i = 0; i < n_; ++i)
      if (!axes_[i]) return end(false, false, AxisError::Disabled);
    for (std::uint32_t i = 0; i < n_; ++i) {
      Command c;
      c.kind = CommandKind::GroupMove;
      c.position = in<double>(kGmPosition, i);
      r_[i] = c.position;
      AxisError e = AxisError::None;
      ids_[i] = axes_[i]->submit(c, ctx.block, &e);
      // A refused axis ends the group; those accepted before it are not fed
      // and brake on their own at their next scan.
      if (!ids_[i]) return end(false, false, e);
    }
    for (std::uint32_t i = 0; i < n_; ++i) {
      const AxisMachine& m = axes_[i]->machine();
      core_.start(i, m.set_position(), m.set_velocity());
      bounds(i);
    }
    running_ = true;
    out_.busy = out_.active = true;
    step();
  }

  void follow() noexcept {
    if (lost_) return end(false, true, AxisError::None);
    std::uint32_t done = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      const CommandReport r = axes_[i]->machine().report(ids_[i]);
      if (r.status == CommandStatus::Active) continue;
      if (r.status == CommandStatus::Done) {
        ++done;
        continue;
      }
      // Another command took an axis over, or an axis went to ErrorStop:
      // the group ends and the others, no longer fed, brake.
      if (r.status == CommandStatus::Error) return end(false, false, r.error);
      return end(false, true, AxisError::None);
    }
    if (done == n_) return end(true, false, AxisError::None);
    if (update_ && in<bool>(kGmUpdate)) {
      for (std::uint32_t i = 0; i < n_; ++i) {
        const double r = in<double>(kGmPosition, i);
        const AxisLimits& l = axes_[i]->machine().limits();
        // A new target beyond a software limit is not taken (the last holds).
        if (!std::isfinite(r) || (l.sw_limit_pos_on && r > l.sw_limit_pos) || (l.sw_limit_neg_on && r < l.sw_limit_neg))
          continue;
        r_[i] = r;
        bounds(i);
      }
    }
    step();
  }

  // One sample of the synchronizer, fed to every axis for its next scan.
  // dt 0: exactly one sample per scan, in step with the axes (the core would
  // catch up skipped releases; an axis steps once per scan).
  void step() noexcept {
    motion::TransientSyncCore::ScanInputs in;
    in.r = r_.data();
    in.r_dot = r_dot_.data();
    in.v_min = v_min_.data();
    in.v_max = v_max_.data();
    in.a_min = a_min_.data();
    in.a_max = a_max_.data();
    core_.scan(in);
    const bool arrived = core_.status().synchronized;
    // The core counts samples from the one the axes have now to the first
    // that tracks; the axes stand exactly at their targets (the done sample
    // fed then) one scan later.
    remaining_ = core_.status().arrival + 1;
    const auto a = core_.x_ddot();
    for (std::uint32_t i = 0; i < n_; ++i)
      axes_[i]->machine().feed(ids_[i], arrived ? motion::FilterState{r_[i], 0} : core_.state(i), a[i], remaining_,
                               arrived);
  }

  std::uint32_t n_;
  motion::TransientSyncCore core_;
  std::vector<AxisBlock*> axes_;
  std::vector<CommandId> ids_;
  std::vector<double> r_, r_dot_, v_min_, v_max_, a_min_, a_max_;
  ExecuteOutputs out_{};
  std::int64_t remaining_ = -1;
  bool execute_before_ = false, running_ = false, update_ = false, lost_ = false, ended_ = false, shown_ = false;
};

std::unique_ptr<Block> make_group_move(BlockSetup& s) {
  const auto n = static_cast<std::uint32_t>(s.param<std::int32_t>("n"));
  return std::make_unique<GroupMove>(n, static_cast<double>(s.task_period_ns()) * 1e-9);
}

}  // namespace

void register_group_move(BlockRegistry& r) {
  BlockTypeInfo t;
  t.name = "MC_GroupMoveAbsolute";
  t.category = kCategory;
  t.doc =
      "Moves the n axes of Axes to Position (one element each) so that all arrive on the same scan, each within its "
      "own MaxVelocityAppl, MaxAccelerationAppl and MaxDecelerationAppl: paper 004's synchronizer (the algorithm of "
      "TRANSIENT_SYNC) lowers the velocity bound of every axis that would arrive before the slowest. The axes start "
      "from their set positions and velocities (moving or standing) and are in DiscreteMotion; Done once all arrived. "
      "With ContinuousUpdate TRUE at the Execute edge, changes of Position while Busy re-target the move in flight "
      "and the axes still arrive together. RemainingScans: scans to the common arrival. Another command to one axis, "
      "or an axis in ErrorStop, ends the group (CommandAborted or Error) and the other axes brake to standstill. Not "
      "on modulo axes.";
  t.reference = "paper 004 (Guarino Lo Bianco), Section III, eqs. 23-34; PLCopen Motion Control Part 1 v2.0, 2.4.1";
  t.pins = {
      input("Execute", IecType::BOOL).doc("rising edge: the group move starts from where the axes are"),
      input("ContinuousUpdate", IecType::BOOL).doc("TRUE at the edge: Position is followed while Busy"),
      input("Position", IecType::LREAL).array("n").doc("target of each axis, user units"),
      output("Done", IecType::BOOL).doc("every axis arrived, on the same scan"),
      output("Busy", IecType::BOOL).doc("the move has not ended"),
      output("Active", IecType::BOOL).doc("the move has the axes"),
      output("CommandAborted", IecType::BOOL).doc("another command took an axis over, or MC_Power switched one off"),
      output("Error", IecType::BOOL).doc("an axis refused the move or went to ErrorStop"),
      output("ErrorID", IecType::WORD).doc("why (docs/motion/plcopen.md, \"Error IDs\")"),
      output("RemainingScans", IecType::LINT).doc("scans until every axis arrives; 0 when done, -1 when not moving"),
  };
  t.params = {
      parameter("n", IecType::DINT).min(1.0).max(1024.0).doc("number of axes"),
  };
  t.links = {LinkDecl{"Axes", kAxisType, "the MC_AXIS instances moved together, one per Position element", "n"}};
  t.create = make_group_move;
  r.add(std::move(t));
}

}  // namespace syncplc::plcopen
