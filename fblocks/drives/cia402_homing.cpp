// CiA 402 homing mode, the master's side (cia402_homing.hpp).
#include "fblocks/drives/cia402_homing.hpp"

#include "fblocks/drives/cia402_math.hpp"

namespace syncplc::drives::cia402 {

HomingOutputs HomingMaster::step(const HomingInputs& in) noexcept {
  HomingOutputs o;
  if (!in.request) {
    // Not asked, or the program took the request back: bit 4 falls (the
    // drive interrupts a homing in progress), for one scan still in homing
    // mode, then the mode returns.
    phase_ = phase_ == Phase::kIdle || phase_ == Phase::kLeaving || phase_ == Phase::kEnterMode ? Phase::kIdle
                                                                                                : Phase::kLeaving;
    armed_ = false;
    o.active = phase_ == Phase::kLeaving;
    return o;
  }
  if (phase_ == Phase::kIdle || phase_ == Phase::kLeaving) phase_ = Phase::kEnterMode;
  // A homing needs Operation enabled throughout; a drive that leaves it
  // (fault, quick stop, power loss) has not homed.
  if ((phase_ == Phase::kEnterMode || phase_ == Phase::kStarted) && in.link_ok && !in.enabled) phase_ = Phase::kError;
  if (in.link_ok && phase_ != Phase::kError && phase_ != Phase::kAttained && in.mode_display == mode::kHoming) {
    const bool b10 = (in.statusword & sw::kTargetReached) != 0;
    const bool b12 = (in.statusword & sw::kHomingAttained) != 0;
    const bool b13 = (in.statusword & sw::kHomingError) != 0;
    const std::uint16_t bits = in.statusword & (sw::kHomingError | sw::kHomingAttained | sw::kTargetReached);
    if ((!b12 && !b13) || (phase_ == Phase::kStarted && bits != start_bits_)) armed_ = true;
    if (phase_ == Phase::kEnterMode) {
      phase_ = Phase::kStarted;  // in homing mode: bit 4 rises from this scan on
      start_bits_ = bits;
    } else if (armed_ && b13) {
      phase_ = Phase::kError;
    } else if (armed_ && b12 && b10) {
      phase_ = Phase::kAttained;
    }
  }
  o.active = true;
  o.start = phase_ == Phase::kStarted || phase_ == Phase::kAttained;
  o.attained = phase_ == Phase::kAttained;
  o.error = phase_ == Phase::kError;
  o.busy = phase_ == Phase::kEnterMode || phase_ == Phase::kStarted;
  return o;
}

}  // namespace syncplc::drives::cia402
