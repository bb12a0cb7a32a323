// Runs one block instance on its own, outside any project: the fixture for
// unit tests of block types (and for users testing their own blocks).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"

namespace syncplc {

class BlockHarness : private EventSink {
 public:
  struct Options {
    std::map<std::string, std::string> params;  // literals, as in a project file
    std::optional<IecType> datatype;            // generic type of the instance
    std::optional<std::set<std::string>> connected;  // default: every input counts as connected
    std::int64_t period_ns = 1'000'000;
    std::uint64_t seed = 1;
  };

  BlockHarness(const BlockRegistry& registry, const std::string& type_name, Options options);
  BlockHarness(const BlockRegistry& registry, const std::string& type_name)
      : BlockHarness(registry, type_name, Options{}) {}

  bool ok() const { return errors_.empty() && block_ != nullptr; }
  const std::vector<std::string>& errors() const { return errors_; }

  template <class T>
  void set(const std::string& pin, T v) { cell(pin).set<T>(v); }
  template <class T>
  T get(const std::string& pin) { return cell(pin).get<T>(); }
  Cell& cell(const std::string& pin);
  // Element i (0-based) of an array pin.
  template <class T>
  void set(const std::string& pin, std::uint32_t i, T v) { cell(pin, i).set<T>(v); }
  template <class T>
  T get(const std::string& pin, std::uint32_t i) { return cell(pin, i).get<T>(); }
  Cell& cell(const std::string& pin, std::uint32_t i);
  std::uint32_t length(const std::string& pin) const;

  // One scan at the current time, under the finite-input rule and with the
  // tuning inputs (finite_guard.hpp), then time advances by one period.
  void scan();
  // A scan of the task in which this block did not execute (time advances by
  // one period; the next scan sees dt = one period, as in a task).
  void skip_scan();
  // Runs `n` scans.
  void scans(int n) { for (int i = 0; i < n; ++i) scan(); }
  std::int64_t now_ns() const { return now_; }
  void set_now_ns(std::int64_t t) { now_ = t; }
  void set_period_ns(std::int64_t p) { period_ = p; }
  std::int64_t consumed_ns() const { return last_consumed_; }
  Block& block() { return *block_; }
  const std::vector<Event>& events() const { return events_; }

 private:
  void push(const Event& e) noexcept override { events_.push_back(e); }

  const BlockTypeInfo* type_ = nullptr;
  std::vector<Cell> cells_;               // every pin's elements, pin after pin
  std::vector<std::uint32_t> first_, length_;  // per pin: first cell, elements
  std::vector<Cell*> pin_ptrs_;
  std::unique_ptr<Block> block_;
  std::vector<std::string> errors_;
  std::vector<Event> events_;
  std::int64_t now_ = 0;
  std::int64_t prev_ = 0;
  std::int64_t period_;
  std::uint64_t scan_ = 0;
  std::int64_t last_consumed_ = 0;
};

}  // namespace syncplc
