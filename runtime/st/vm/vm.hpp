// The interpreter of compiled Structured Text (code.hpp): runs one POU's code
// on one frame. Scan path: no allocation, no lock, no exception, no I/O; a
// fault raises an event with static text and the code goes on with the
// defined value; a loop that exhausts the budget stops the whole call chain.
#pragma once

#include <cstddef>
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

  // The block instances of the project the POU's AXIS_REFs name: an
  // AXIS_REF holds k + 1 for targets[k] (0: none). Set by the owner
  // (StBlock::link) before the first scan and after every online change.
  Block* const* targets = nullptr;
  std::uint32_t target_count = 0;

  void fault(std::uint32_t site, double value = 0) noexcept;
};

// Runs POU `pou` of vm.module on `frame`. False when the loop budget ran out
// (vm.stopped names the loop); the callers unwind at once.
bool run(Vm& vm, std::uint32_t pou, Cell* frame) noexcept;
// The same for a POU already looked up: an instance keeps its POU at hand,
// so a scan starts without walking module -> pous -> POU first.
bool run(Vm& vm, const CompiledPou& pou, Cell* frame) noexcept;

// How a module's POUs run. Native: as x86-64 machine code made at load
// (native_x64.cpp), on machines where that exists and the system lets a
// process map code; the interpreter otherwise, and everywhere for the
// instructions native code has no template of. Both give the same bits
// (docs/st.md, "How compiled ST runs").
enum class Engine { Native, Interpreter };

// Resolves every instruction's handler (direct threading), then makes the
// engine's code; once per module, after code generation and before the
// first run.
void finalize(Module& m, Engine engine = Engine::Native);
// Switches a finalized module's engine (tests and benchmarks compare them);
// not while it runs. Native where it cannot be made stays interpreted.
void set_engine(Module& m, Engine engine);
// The POUs of `m` that run as native code, and the loops in them that keep
// cells in registers (native_loops.hpp).
std::size_t native_pous(const Module& m);
std::size_t native_register_loops(const Module& m);

// One instruction of `pou` at `pc` run by the interpreter: the next pc, or
// one of these. Native code's way into the interpreter.
inline constexpr std::uint32_t kStepHalted = 0xFFFF'FFFFu;   // HALT: the POU returned
inline constexpr std::uint32_t kStepStopped = 0xFFFF'FFFEu;  // the loop budget ran out
std::uint32_t step(Vm* vm, const CompiledPou* pou, Cell* frame, std::uint32_t pc) noexcept;

}  // namespace syncplc::st::vm
