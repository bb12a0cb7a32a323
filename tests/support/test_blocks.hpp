// Block types that exist only for the runtime's own tests: they record what
// the scheduler does, or poke at things mid-scan.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/block.hpp"

namespace syncplc::testing {

struct ScanRecord {
  std::string instance;
  std::uint16_t task;
  std::int64_t now_ns;
  std::int64_t dt_ns;
  std::uint64_t scan;
  double in;  // value of the recorder's IN pin during the scan
};

// Everything RECORD blocks saw, in execution order (single-threaded use only).
std::vector<ScanRecord>& records();

// Called by HOOK blocks during their execute(); set by a test.
std::function<void(ScanContext&)>& hook();

// HANG blocks: once hang_armed() is set, the next scan that runs one does not
// end until hang_release() is set (a block that loops forever, for the
// supervisor's tests; the test releases it so that its thread can be joined).
std::atomic<bool>& hang_armed();
std::atomic<bool>& hang_release();

// builtin blocks plus:
//   RECORD (IN LREAL -> OUT LREAL): appends a ScanRecord, OUT := IN
//   HOOK   (IN LREAL -> OUT LREAL): calls hook(), OUT := IN
//   HANG   (IN LREAL -> OUT LREAL): OUT := IN; loops while hang_armed() and not hang_release()
//   STAMP  (-> OUT LREAL[pins A,B,C,D]): writes ctx.now_ns in ms to four outputs,
//          so a reader can check that four values published together stay together
//   ARRAY_GAIN (IN ARRAY[1..N] OF LREAL -> OUT ARRAY[1..N], SUM, FLAGS ARRAY[1..N] OF BOOL;
//          params N (INT, default 3), GAIN (LREAL, default 2)): OUT[i] := GAIN*IN[i], SUM := sum IN,
//          FLAGS[i] := IN[i] > 0 — the array-pin test block
//   ACC    (IN LREAL -> SUM LREAL; params K tunable, MODE structural): SUM += K*IN — state for online change
//   LOG    (IN LREAL -> OUT LREAL; param N, default 100000): keeps (release time, IN) of
//          its first N scans in memory sized at load — a trace a real-time thread can write
const BlockRegistry& test_blocks();

// The LOG block: what it kept (read once its task has stopped).
class LogBlock final : public Block {
 public:
  struct Sample {
    std::int64_t now_ns;
    double in;
  };
  explicit LogBlock(std::size_t capacity) : samples_(capacity) {}
  void execute(ScanContext& ctx) noexcept override {
    const double v = in<double>(0);
    if (n_ < samples_.size()) samples_[n_++] = Sample{ctx.now_ns, v};
    out<double>(1, v);
  }
  std::vector<Sample> samples() const { return {samples_.begin(), samples_.begin() + static_cast<std::ptrdiff_t>(n_)}; }

 private:
  std::vector<Sample> samples_;
  std::size_t n_ = 0;
};

// Writes `text` to a temporary file and returns its path.
std::string write_temp_file(const std::string& name, const std::string& text);

}  // namespace syncplc::testing
