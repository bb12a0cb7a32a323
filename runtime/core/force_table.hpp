// Forces on a task's side (docs/user-guide.md, "Forcing and monitoring"):
// the elements of this task's image that hold a forced value whatever the
// program, a driver or a writer from outside puts there, and where in the
// scan each is put back. Capacity is fixed at load (the project's
// max_forces); the table is touched only by the thread that scans the task
// (commands arrive through the task's write queue, QueuedWrite::kind), so
// nothing here locks or allocates.
//
// Where a force holds (Task::scan):
//   every force          at the scan's start, after the queued writes: an
//                        outside write to a forced element changes nothing
//   ForcePoint::Driver   after the drivers latched their inputs
//   ForcePoint::BlockTag after the writing block's outputs were copied, so
//                        every block reading the tag later in the scan
//                        sees the forced value
//   ForcePoint::PinIn    after the block's input copy: the block sees it
//   ForcePoint::PinOut   after the block executed: its output copies (tags,
//                        pins of later blocks) take the forced value
// A tag bound to a driver output is written to the driver with its forced
// value (write_outputs runs after all of the above).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

// Forces a project allows at once unless its `project: max_forces` says otherwise.
inline constexpr std::size_t kDefaultMaxForces = 64;
inline constexpr std::size_t kMaxMaxForces = 4096;

enum class ForcePoint : std::uint8_t {
  Tag,       // a tag nothing in the scan writes (set from outside, or by its init): held from the scan's start
  Driver,    // a tag a driver input latches
  BlockTag,  // a tag a block's output is copied to
  PinIn,     // an input pin of a block
  PinOut,    // an output pin of a block
};
std::string_view force_point_name(ForcePoint p);

inline constexpr std::uint32_t kNoBlock = std::numeric_limits<std::uint32_t>::max();

struct ForceSlot {
  std::uint32_t cell = 0;        // in the task's image
  std::uint32_t block = kNoBlock;  // BlockTag, PinIn, PinOut: the block's position in the execution order
  ForcePoint point = ForcePoint::Tag;
  bool restore = false;          // unforce puts `saved` back (an unconnected input: its constant)
  Cell value;
  Cell saved;                    // the cell before the first force
};

class ForceTable {
 public:
  // At load, before the task runs.
  void reserve(std::size_t capacity) {
    slots_.assign(capacity, ForceSlot{});
    n_ = 0;
    drivers_ = 0;
  }
  std::size_t capacity() const noexcept { return slots_.size(); }
  std::size_t size() const noexcept { return n_; }
  bool empty() const noexcept { return n_ == 0; }
  bool has_driver_inputs() const noexcept { return drivers_ != 0; }

  // Adds a force or changes the value of one on the same cell. The cell's
  // value is saved the first time (for `restore`). Returns false when the
  // table is full (the Program's registry keeps that from happening), and
  // *added whether this is a new force (not a changed value).
  bool set(const ForceSlot& s, Cell* image, bool* added) noexcept;
  // Removes the force on `cell` (putting the saved value back when the slot
  // says so); *removed receives it. False when the cell was not forced.
  bool clear(std::uint32_t cell, Cell* image, ForceSlot* removed) noexcept;

  void apply_all(Cell* image) const noexcept {
    for (std::size_t i = 0; i < n_; ++i) image[slots_[i].cell] = slots_[i].value;
  }
  void apply(Cell* image, ForcePoint p, std::uint32_t block = kNoBlock) const noexcept {
    for (std::size_t i = 0; i < n_; ++i)
      if (slots_[i].point == p && slots_[i].block == block) image[slots_[i].cell] = slots_[i].value;
  }
  const ForceSlot* begin() const noexcept { return slots_.data(); }
  const ForceSlot* end() const noexcept { return slots_.data() + n_; }

 private:
  std::vector<ForceSlot> slots_;  // [0, n_) active, in no particular order
  std::size_t n_ = 0;
  std::size_t drivers_ = 0;       // active slots at ForcePoint::Driver
};

}  // namespace syncplc
