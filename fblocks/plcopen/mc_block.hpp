// What every MC_* block shares: the link to its axis, and the output rules of
// PLCopen Part 1 v2.0 §2.4.1 for blocks started by Execute's rising edge.
#pragma once

#include <cstdint>

#include "fblocks/plcopen/axis_block.hpp"
#include "runtime/core/block.hpp"

namespace syncplc::plcopen {

// The outputs of an Execute block (§2.4.1): Busy, Active, Done,
// CommandAborted and Error are exclusive; Done, CommandAborted and Error
// (with ErrorID) stay while Execute is TRUE and fall with it, and are shown
// for at least one scan even when Execute fell before they came.
struct ExecuteOutputs {
  bool busy = false;
  bool active = false;
  bool done = false;
  bool aborted = false;
  bool error = false;
  std::uint16_t error_id = 0;
  bool in_velocity = false;  // MC_MoveVelocity's InVelocity (while Active)
};

// Tracks one block's command on its axis from Execute's rising edge to its
// end. `submit` is called at the edge and returns the id (0 with *error set
// when the axis refused the command).
class ExecuteTracker {
 public:
  template <class Submit>
  void update(bool execute, const AxisMachine* axis, Submit&& submit) noexcept {
    const bool rising = execute && !execute_before_;
    execute_before_ = execute;
    if (rising) {
      // §2.4.1-j: a new command of the same instance; nothing more is
      // reported of the one before.
      out_ = {};
      id_ = 0;
      ended_ = false;
      AxisError e = AxisError::None;
      if (axis) id_ = submit(&e);
      else e = AxisError::Disabled;
      if (!id_) end_with_error(e);
      else follow(axis->report(id_));  // Busy (and Active unless buffered) from the edge on
    } else if (id_ && axis) {
      follow(axis->report(id_));
    }
    if (ended_) {
      // Shown once with Execute low, then cleared (§2.4.1-i).
      if (!execute && shown_) {
        out_ = {};
        ended_ = false;
      } else {
        shown_ = true;
      }
    }
  }
  // The axis object changed (an online change re-created it): the command
  // is gone with it.
  void axis_changed() noexcept {
    if (id_) {
      id_ = 0;
      out_ = {};
      out_.aborted = true;
      mark_ended();
    }
  }
  const ExecuteOutputs& outputs() const noexcept { return out_; }
  CommandId command() const noexcept { return id_; }
  // For MC_Stop: the stop this instance gave, kept after its Done.
  CommandId last_command() const noexcept { return last_id_; }
  bool execute() const noexcept { return execute_before_; }

 private:
  void follow(const CommandReport& r) noexcept {
    last_id_ = id_;
    switch (r.status) {
      case CommandStatus::Buffered:
        out_.busy = true;
        out_.active = false;
        break;
      case CommandStatus::Active:
        out_.busy = true;
        out_.active = true;
        out_.in_velocity = r.in_velocity;
        break;
      case CommandStatus::Done:
        out_ = {};
        out_.done = true;
        mark_ended();
        break;
      case CommandStatus::Error:
        end_with_error(r.error);
        break;
      case CommandStatus::Aborted:
      case CommandStatus::Unknown:  // left the axis's report table: it can only have been taken over
        out_ = {};
        out_.aborted = true;
        mark_ended();
        break;
    }
  }
  void end_with_error(AxisError e) noexcept {
    out_ = {};
    out_.error = true;
    out_.error_id = static_cast<std::uint16_t>(e);
    mark_ended();
  }
  void mark_ended() noexcept {
    if (id_) last_id_ = id_;
    id_ = 0;
    ended_ = true;
    shown_ = false;
  }

  ExecuteOutputs out_{};
  CommandId id_ = 0;
  CommandId last_id_ = 0;
  bool execute_before_ = false;
  bool ended_ = false;  // Done, CommandAborted or Error is set
  bool shown_ = false;  // ... and was output at least once
};

// The base of the MC_* blocks: the link to the axis (BlockTypeInfo::links[0],
// `Axis`).
class McBlock : public Block {
 public:
  void link(int link, std::uint32_t element, Block& target) noexcept override {
    (void)link;
    (void)element;
    auto* axis = dynamic_cast<AxisBlock*>(&target);
    if (axis != axis_) {
      const bool had = axis_ != nullptr;
      axis_ = axis;
      if (had) axis_changed();
    }
  }

 protected:
  // The linked axis went away (re-created by an online change).
  virtual void axis_changed() noexcept {}
  AxisBlock* axis_ = nullptr;
};

// The link every MC_* block declares.
LinkDecl axis_link();

}  // namespace syncplc::plcopen
