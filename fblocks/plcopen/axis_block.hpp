// MC_AXIS: one PLCopen axis as a block instance, the AXIS_REF that the MC_*
// blocks name in their `Axis` link (params: {Axis: x}). It owns the axis
// machine (axis_machine.hpp) and is the axis's one door to its drive: the
// actual values and the drive's state come in on its input pins, the set
// values and the enable go out on its output pins, wired in the project to a
// CIA402_DRIVE, a sim_table axis (through a position controller) or a
// SIM_SERVO.
//
// A unit delay (BlockTypeInfo::unit_delay): it runs first in its task's scan
// and makes this scan's set values from the feedback of the scan before
// (end_of_scan samples it), so a drive block fed by it and feeding it back
// makes no loop. The MC_* blocks linked to it run after it: they see this
// scan's state and their commands shape the next scan's set values.
#pragma once

#include <array>
#include <cstdint>
#include <utility>

#include "fblocks/plcopen/axis_machine.hpp"
#include "runtime/core/block.hpp"

namespace syncplc::plcopen {

inline constexpr const char* kAxisType = "MC_AXIS";

// Pins of MC_AXIS, in declaration order.
enum AxisPin : int {
  kAxActualPosition = 0,
  kAxActualVelocity,
  kAxFeedbackOk,
  kAxPowerOn,
  kAxFault,
  kAxFaultCode,
  kAxHomeSwitch,
  kAxHomingAttained,
  kAxHomingError,
  kAxEnable,
  kAxReset,
  kAxDrivePosition,
  kAxDriveVelocity,
  kAxDriveAcceleration,
  kAxState,
  kAxPosition,
  kAxVelocity,
  kAxSetPosition,
  kAxSetVelocity,
  kAxFollowingError,
  kAxError,
  kAxErrorId,
  kAxDriveFaultCode,
  kAxHomed,
  kAxCommand,
  kAxCommandBlock,
  kAxRemainingScans,
  // The HMI's door to the axis (POST /api/v1/axes/{name}/enable|disable|reset,
  // written through the task's write queue; docs/http-api.md "Axes").
  kAxHmiEnable,
  kAxHmiReset,
  kAxPowered,
  kAxHome,
  kAxDriveHomeMethod,
  kAxDriveHomePosition,
};

class AxisBlock final : public Block {
 public:
  AxisBlock(const AxisLimits& limits, double period_s, double scale, bool velocity_wired, bool power_wired) noexcept
      : limits_(limits),
        machine_(limits, period_s),
        scale_(scale),
        velocity_wired_(velocity_wired),
        power_wired_(power_wired) {}

  void execute(ScanContext& ctx) noexcept override;
  void end_of_scan() noexcept override;
  // The limits are tunable: an online change or a tuning input <limit>_in
  // changes them on the running axis (AxisMachine::retune), which keeps its
  // state, its commands and its motion.
  void retune_from(const Block& fresh) noexcept override;
  bool tune(int param, double value) noexcept override;

  AxisMachine& machine() noexcept { return machine_; }
  const AxisMachine& machine() const noexcept { return machine_; }
  // A motion block's command, with the block that gave it (its position in
  // the task's order, shown by the `command_block` output while it runs).
  CommandId submit(const Command& c, std::int32_t block, AxisError* error) noexcept;
  std::int32_t source_of(CommandId id) const noexcept;  // -1 when unknown

 private:
  AxisLimits limits_;    // the system limits, as the parameters give them
  AxisMachine machine_;
  double scale_;          // drive units per user unit
  bool velocity_wired_;   // else the actual velocity is the actual position's backward difference
  bool power_wired_;      // else the power stage follows the enable output (an ideal drive)
  DriveFeedback next_{};  // sampled at the end of the scan, for the next one
  bool sampled_ = false;  // end_of_scan ran since the last execute (a non-finite input skips it)
  bool have_position_ = false;
  double last_position_ = 0;
  // Which block gave each recent command (the active one and those buffered).
  std::array<std::pair<CommandId, std::int32_t>, AxisMachine::kQueueCapacity + 2> sources_{};
  std::size_t next_source_ = 0;

  // The HMI's permissive and reset request (hmi_enable, hmi_reset): before
  // and after the machine's cycle (axis_block.cpp).
  void hmi_permissive() noexcept;
  void hmi_reset() noexcept;
};

}  // namespace syncplc::plcopen
