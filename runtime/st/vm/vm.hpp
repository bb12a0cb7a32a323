// The interpreter of compiled Structured Text (code.hpp): runs one POU's code
// on one frame. Scan path: no allocation, no lock, no exception, no I/O; a
// fault raises an event with static text and the code goes on with the
// defined value; a loop that exhausts the budget stops the whole call chain.
#pragma once

#include <cstdint>

#include "runtime/core/block.hpp"
#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

struct Vm {
  const Module* module = nullptr;
  Cell* functions = nullptr;  // the FUNCTIONs' static frames (Module::function_area cells)
  Cell* scratch = nullptr;    // where an out-of-bounds index points (Module::scratch_cells)
  ScanContext* ctx = nullptr; // faults become its events; null in unit tests
  // Backward jumps left in this scan (the loop budget, docs/st.md).
  std::int64_t budget = 0;
  // The site of the loop that exhausted the budget, or nullptr.
  const char* stopped = nullptr;
  // Faults raised (also without a context), and the last one's text.
  std::uint64_t faults = 0;
  const char* last_fault = nullptr;

  void fault(std::uint32_t site, double value = 0) noexcept;
};

// Runs POU `pou` of vm.module on `frame`. False when the loop budget ran out
// (vm.stopped names the loop); the callers unwind at once.
bool run(Vm& vm, std::uint32_t pou, Cell* frame) noexcept;
// The same for a POU already looked up: an instance keeps its POU at hand,
// so a scan starts without walking module -> pous -> POU first.
bool run(Vm& vm, const CompiledPou& pou, Cell* frame) noexcept;

// Resolves every instruction's handler (direct threading); once per module,
// after code generation and before the first run.
void finalize(Module& m);

}  // namespace syncplc::st::vm
