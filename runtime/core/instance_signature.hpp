// What identifies a block instance and a tag from one load of a project to
// the next: the one signature that online change, retain and the historian
// share (issue 21). The loader computes it; nothing else builds one.
//
// A block instance's signature has four parts, compared in this order:
//   structure  block type with its datatype ("CTU<INT>"), array pin sizes,
//              the parameters that are not tunable and the instances it is
//              linked to: a difference re-creates the instance;
//   wiring     which pins are fed and from where, and the task period if the
//              factory read it (a filter's sampling time). What the factory fixed
//              from the wiring when it built the instance (a pin it asked
//              BlockSetup::connected about, a connected tuning input) is
//              behaviour: a difference there means the running instance
//              would go on with its old wiring, so it is rewired (the block
//              type takes it from a fresh instance, Block::rewire_from) or
//              re-created. Where a pin is fed from (another tag, a constant)
//              only changes the copies around the block;
//   tuning     tunable parameters: a difference retunes (Block::retune_from);
//   state      the block's state cells and their layout (Block::retain_cells,
//              retain_layout): a re-created instance takes the old one's state
//              where this part is equal and the instance is persistent, as a
//              stop and start would have restored it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

struct BlockTypeInfo;
struct Tag;

// How one pin is fed, as the project says it.
struct PinFeed {
  enum class Kind : std::uint8_t { None, Constant, Wired };
  Kind kind = Kind::None;
  std::string from;  // Wired: the source as written ("start_ok", "pid.y", "x[2]"; elements "x[1],-,x[3]")
  bool operator==(const PinFeed&) const = default;
};

// What the factory read of the wiring: per pin, not asked, or asked and
// answered unwired or wired.
enum class WiringSeen : std::uint8_t { NotAsked, Unwired, Wired };

struct StateLayout {
  std::uint32_t cells = 0;   // Block::retain_cells()
  std::uint32_t layout = 1;  // Block::retain_layout()
  bool operator==(const StateLayout&) const = default;
};

struct InstanceSignature {
  const BlockTypeInfo* type = nullptr;
  std::string type_name;                   // "CTU<INT>" for a generic type, else the type's name
  std::vector<std::uint32_t> pin_length;   // by pin index
  std::vector<Cell> params;                // by ParamDecl index
  std::vector<std::string> links;          // by LinkDecl index: the target instance's name (a list's names joined by ",")
  std::vector<PinFeed> feeds;              // by pin index (outputs: None)
  std::vector<WiringSeen> seen;            // by pin index
  // The task period the factory read (BlockSetup::task_period_ns: a filter's
  // sampling time), 0 when it did not: a re-timed task's instance that fixed
  // it is rewired or re-created, never kept on the old period.
  std::int64_t period_ns = 0;
  StateLayout state;

  // "CTU<INT> state 1 (2 cells)": what a stored state must match to be
  // restored (retain) or carried over (online change).
  std::string state_identity() const;
};

// What an online change does with an instance, from its old and new signature.
enum class SignatureVerdict : std::uint8_t {
  Same,      // keep the running instance as it is
  Retune,    // keep it, take the new tunable parameters
  Rewire,    // keep it, take what its factory fixed from the new wiring (and the tunables)
  Recreate,  // the new instance replaces it
};

struct SignatureDiff {
  SignatureVerdict verdict = SignatureVerdict::Same;
  std::string detail;  // for the change report: "IN3 now wired (estop_ok)", "Kp 1 -> 2", "type PID -> PD_CONTROLLER"
  bool state_matches = false;  // Recreate: the old state fits the new instance (same state_identity)
};

// Rewire needs a type that implements Block::rewire_from (BlockTypeInfo::
// rewire) unless only tuning inputs changed, which every type takes.
SignatureDiff compare_signatures(const InstanceSignature& old_sig, const InstanceSignature& new_sig);

// A tag's identity: "DINT", "ARRAY[1..4] OF LREAL". Two tags of one name are
// the same variable when this is equal (online change carries the value,
// retain restores it, the historian goes on with its series).
std::string tag_identity(const Tag& t);

}  // namespace syncplc
