#include "runtime/core/force_table.hpp"

namespace syncplc {

std::string_view force_point_name(ForcePoint p) {
  switch (p) {
    case ForcePoint::Tag: return "tag";
    case ForcePoint::Driver: return "driver input";
    case ForcePoint::BlockTag: return "block output tag";
    case ForcePoint::PinIn: return "input pin";
    case ForcePoint::PinOut: return "output pin";
  }
  return "?";
}

bool ForceTable::set(const ForceSlot& s, Cell* image, bool* added) noexcept {
  *added = false;
  for (std::size_t i = 0; i < n_; ++i)
    if (slots_[i].cell == s.cell) {
      slots_[i].value = s.value;  // a changed value; the saved one stays the one from before the first force
      return true;
    }
  if (n_ == slots_.size()) return false;
  ForceSlot& slot = slots_[n_++];
  slot = s;
  slot.saved = image[s.cell];
  if (s.point == ForcePoint::Driver) ++drivers_;
  *added = true;
  return true;
}

bool ForceTable::clear(std::uint32_t cell, Cell* image, ForceSlot* removed) noexcept {
  for (std::size_t i = 0; i < n_; ++i) {
    if (slots_[i].cell != cell) continue;
    *removed = slots_[i];
    if (removed->restore) image[cell] = removed->saved;
    if (removed->point == ForcePoint::Driver) --drivers_;
    slots_[i] = slots_[--n_];
    return true;
  }
  return false;
}

}  // namespace syncplc
