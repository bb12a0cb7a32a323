// The axis's numbers in words (axis_texts.hpp).
#include "fblocks/plcopen/axis_texts.hpp"

// A command kind or error the axis gains without its words here fails the
// build, not the operator's faceplate (which would show "unknown").
#pragma GCC diagnostic error "-Wswitch"

namespace syncplc::plcopen {

const char* command_kind_name(CommandKind k) noexcept {
  switch (k) {
    case CommandKind::MoveAbsolute: return "MoveAbsolute";
    case CommandKind::MoveRelative: return "MoveRelative";
    case CommandKind::MoveAdditive: return "MoveAdditive";
    case CommandKind::MoveVelocity: return "MoveVelocity";
    case CommandKind::Halt: return "Halt";
    case CommandKind::Stop: return "Stop";
    case CommandKind::Home: return "Home";
    case CommandKind::GroupMove: return "GroupMove";
    case CommandKind::Synchronized: return "Synchronized";
    case CommandKind::SyncOut: return "SyncOut";
  }
  return "unknown";
}

const char* axis_error_text(AxisError e) noexcept {
  switch (e) {
    case AxisError::None: return "";
    case AxisError::Disabled: return "a motion command to a Disabled axis";
    case AxisError::InErrorStop: return "a motion command to an axis in ErrorStop";
    case AxisError::Stopping: return "a motion command while MC_Stop holds the axis";
    case AxisError::NotStandstill: return "MC_Home or MC_SetPosition outside Standstill";
    case AxisError::NotSynchronized: return "MC_GearOut/MC_CamOut outside SynchronizedMotion";
    case AxisError::StillMoving: return "MC_Reset while ErrorStop still brakes the axis";
    case AxisError::MasterFailed: return "MC_GearIn/MC_CamIn: the master is Disabled or in ErrorStop";
    case AxisError::BadVelocity: return "velocity not finite, not positive or above the axis maximum";
    case AxisError::BadAcceleration: return "acceleration not finite, negative or above the axis maximum";
    case AxisError::BadDeceleration: return "deceleration not finite, negative or above the axis maximum";
    case AxisError::BadJerk: return "jerk not finite, negative or above the axis maximum";
    case AxisError::BadPosition: return "position not finite or beyond an enabled software limit";
    case AxisError::BadBufferMode: return "BufferMode not 0-5";
    case AxisError::BufferFull: return "too many buffered commands";
    case AxisError::BadDirection: return "Direction not allowed";
    case AxisError::BadParameter: return "unknown, read-only or out-of-range parameter";
    case AxisError::BadSyncInput: return "gear ratio, cam table, scaling, StartMode or MasterValueSource invalid";
    case AxisError::DriveFault: return "the drive faulted";
    case AxisError::PowerLost: return "the power stage went off while MC_Power asked for it";
    case AxisError::FollowingError: return "following error beyond MaxPositionLag";
    case AxisError::FeedbackLost: return "the drive's feedback is stale";
    case AxisError::SoftLimit: return "a continuous move reached a software limit";
    case AxisError::HomingFailed: return "MC_Home found no reference switch within home_max_distance";
    case AxisError::DriveHomingError: return "the drive reported a homing error (MC_Home, home_mode 3)";
    case AxisError::HomingTimeout: return "the drive's homing not attained within home_timeout";
    case AxisError::SyncLimit: return "a synchronized slave was given a sample beyond its velocity or acceleration limits";
  }
  return "unknown error";
}

}  // namespace syncplc::plcopen
