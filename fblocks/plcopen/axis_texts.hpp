// What the axis's numbers mean in words, for people: the HTTP API's axes
// (GET /api/v1/axes) and the HMI's faceplates show these, the numbers are
// MC_AXIS's `command` and `error_id` outputs (docs/motion/plcopen.md).
#pragma once

#include "fblocks/plcopen/axis_machine.hpp"

namespace syncplc::plcopen {

// "MoveAbsolute", ..., "GroupMove": the block's name without MC_.
const char* command_kind_name(CommandKind k) noexcept;
// One line, as the Error IDs table of docs/motion/plcopen.md says it; "" for
// None, "unknown error" for a number that is none of them.
const char* axis_error_text(AxisError e) noexcept;

}  // namespace syncplc::plcopen
