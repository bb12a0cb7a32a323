// The master side of CiA 402 homing mode (modes of operation 6), without
// pins: when the program asks for homing, the drive is switched to homing
// mode, controlword bit 4 ("homing operation start") rises once the mode
// display shows 6, and statusword bits 10 (target reached), 12 (homing
// attained) and 13 (homing error) tell the end. CIA402_DRIVE
// (cia402_drive.cpp) wraps it; tests/drives/test_cia402_homing.cpp drives it.
//
// The standard (CiA 402-2 / IEC 61800-7-201, homing mode): controlword bit 4
// 0 -> 1 starts homing, 1 -> 0 interrupts it; the statusword in homing mode
// reads (bit 13, bit 12, bit 10):
//   0 0 0 in progress            0 0 1 interrupted or not started
//   0 1 0 attained, target not reached
//   0 1 1 completed successfully
//   1 0 0 error, velocity not 0  1 0 1 error, velocity 0
//
// A statusword read before the drive took the start may still show the end
// of an earlier homing. The master therefore believes "completed" or
// "error" only after the drive has shown that it took this start: since the
// request began, a statusword in homing mode with bits 12 and 13 both 0 (not
// started, or in progress), or bits 13, 12, 10 other than they were when
// bit 4 rose. A drive that ends a homing within one bus cycle with the very
// bits an earlier homing left is never believed (the axis's home_timeout
// ends it). To help drives that clear bits 12 and 13 when bit 4 falls, the
// end of a request drops bit 4 for one scan still in homing mode before the
// mode returns.
#pragma once

#include <cstdint>

namespace syncplc::drives::cia402 {

namespace cw {
inline constexpr std::uint16_t kHomingStart = 1u << 4;  // homing mode: operation start
}
namespace sw {
inline constexpr std::uint16_t kHomingAttained = 1u << 12;  // homing mode
inline constexpr std::uint16_t kHomingError = 1u << 13;     // homing mode
}

struct HomingInputs {
  bool request = false;         // the program asks for homing (level; FALSE interrupts)
  bool enabled = false;         // the drive is in Operation enabled and the goal is to stay there
  bool link_ok = true;          // FALSE: the statusword is stale, nothing is decided
  std::uint16_t statusword = 0;
  int mode_display = 0;         // 6061h
};

struct HomingOutputs {
  bool active = false;          // modes of operation must be 6 (homing mode)
  bool start = false;           // controlword bit 4
  bool attained = false;        // homing completed successfully (bits 12 and 10, after the arming)
  bool error = false;           // homing error (bit 13 after the arming, or the drive left Operation enabled)
  bool busy = false;            // asked, and neither attained nor error yet
};

class HomingMaster {
 public:
  HomingOutputs step(const HomingInputs& in) noexcept;

 private:
  enum class Phase : std::uint8_t { kIdle, kEnterMode, kStarted, kAttained, kError, kLeaving };
  Phase phase_ = Phase::kIdle;
  bool armed_ = false;  // the drive showed it took this start (above)
  std::uint16_t start_bits_ = 0;  // bits 13, 12, 10 when bit 4 rose
};

}  // namespace syncplc::drives::cia402
