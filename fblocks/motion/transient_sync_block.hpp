// Internal to TRANSIENT_SYNC: the order of its pins (that of the declaration
// in transient_sync_info.cpp) and the factory of its scan algorithm
// (transient_sync.cpp), so that the declaration and the algorithm live in
// files of their own.
#pragma once

#include <cstdint>
#include <memory>

#include "runtime/core/block.hpp"

namespace syncplc::motion {

enum TransientSyncPin : int {
  // array inputs
  kR = 0,
  kRDot,
  kVMin,
  kVMax,
  kAMin,
  kAMax,
  kX0,
  kV0,
  // scalar input
  kReset,
  // array outputs
  kX,
  kXDot,
  kXDDot,
  kVMinApplied,
  kVMaxApplied,
  kTracking,
  kStepsToGo,
  kError,
  // scalar outputs
  kArrival,
  kSynchronized,
  kScaled,
  kEnergy,
  kEnergyLast,
  kWindows,
  kWindowScans,
  kSpread,
};

// Most axes of one instance (parameter n).
inline constexpr std::int64_t kMaxAxes = 1024;

// The block for a validated setup (n in 1..kMaxAxes, rule 0..2).
std::unique_ptr<Block> make_transient_sync(BlockSetup& s);

}  // namespace syncplc::motion
