// The memory driver: channels backed by plain memory. Inputs are set from
// outside (tests, simulations, `syncplc test` steps) with force_input();
// outputs keep the last value the PLC wrote (or the safe value the
// supervisor wrote, held from then on). It counts latches and writes so
// tests can check that the scan calls it exactly once each per scan.
#pragma once

#include <atomic>
#include <memory>
#include <vector>

#include "runtime/core/io_driver.hpp"
#include "runtime/io/safe_output_latch.hpp"

namespace syncplc {

class MemoryDriver final : public IoDriver {
 public:
  explicit MemoryDriver(std::vector<DriverChannel> channels);

  const std::vector<DriverChannel>& channels() const override { return channels_; }
  void bind(const std::vector<Cell*>& cells) override { bound_ = cells; }
  bool open(std::string*) override {
    safe_.reset();
    return true;
  }
  void latch_inputs(const ScanContext& ctx) noexcept override;
  void write_outputs(const ScanContext& ctx) noexcept override;
  void close() noexcept override {}
  bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept override;
  bool force_input(int channel, const Cell* values) override;
  bool read_output(int channel, Cell* values) const override;

  int channel_index(const std::string& name) const;
  std::uint64_t latches() const { return latches_.load(std::memory_order_relaxed); }
  std::uint64_t writes() const { return writes_.load(std::memory_order_relaxed); }

 private:
  std::vector<DriverChannel> channels_;
  std::vector<std::uint32_t> offset_;  // first storage cell of each channel
  std::unique_ptr<std::atomic<std::uint64_t>[]> store_;
  std::vector<Cell*> bound_;
  std::atomic<std::uint64_t> latches_{0};
  std::atomic<std::uint64_t> writes_{0};
  SafeOutputLatch safe_;
};

DriverTypeInfo memory_driver_type();

}  // namespace syncplc
