// Fault injection for the `dds` driver's receive thread (docs/dds.md,
// "Injected loss and delay"): samples dropped with a seeded probability, and
// held for a fixed delay before the program may see them. A delay line of
// fixed capacity, allocated at open(), never in the receive loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace syncplc::dds {

template <class T>
class DelayLine {
 public:
  explicit DelayLine(std::size_t capacity = 0) : items_(capacity) {}
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  // The due time of the oldest item (only when not empty).
  std::int64_t next_due() const { return items_[head_].due; }
  // Adds an item due at `due` (due times rise: one fixed delay). When full,
  // the oldest goes first and push returns true ("one dropped").
  bool push(const T& value, std::int64_t due) {
    bool dropped = false;
    if (size_ == items_.size()) {
      if (items_.empty()) return true;
      head_ = (head_ + 1) % items_.size();
      --size_;
      dropped = true;
    }
    Item& it = items_[(head_ + size_) % items_.size()];
    it.value = value;
    it.due = due;
    ++size_;
    return dropped;
  }
  // The oldest item if it is due at `now`.
  const T* pop_due(std::int64_t now) {
    if (size_ == 0 || items_[head_].due > now) return nullptr;
    const T* v = &items_[head_].value;
    head_ = (head_ + 1) % items_.size();
    --size_;
    return v;  // valid until the next push
  }

 private:
  struct Item {
    T value{};
    std::int64_t due = 0;
  };
  std::vector<Item> items_;
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace syncplc::dds
