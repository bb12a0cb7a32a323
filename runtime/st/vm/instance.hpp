// One running instance of a compiled POU (a PROGRAM, or a FUNCTION_BLOCK
// used as a block of the graph): its area of cells — the POU's frame, the
// FUNCTIONs' static frames and the scratch cells of out-of-bounds indexes —
// and the built-in blocks its frame embeds. Created at load; scan() runs it
// once on the scan path.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/st/vm/code.hpp"
#include "runtime/st/vm/vm.hpp"

namespace syncplc::st::vm {

// What the built-in blocks embedded in an instance are created with.
struct InstanceSetup {
  std::string name;                 // the instance's name (built-in blocks: name.member)
  std::int64_t task_period_ns = 0;
  std::uint64_t seed = 0;
};

class Instance {
 public:
  // Throws std::runtime_error naming the built-in block that cannot be
  // created (its factory refused its parameters).
  Instance(std::shared_ptr<const Module> module, std::uint32_t pou, const InstanceSetup& setup);
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  // One execution. False when the loop budget ran out (stopped() names the loop).
  bool scan(ScanContext& ctx, std::int64_t loop_budget) noexcept;

  Cell* frame() noexcept { return frame_; }
  const Cell* frame() const noexcept { return frame_; }
  // The frame moves to `to` (frame_cells() cells): with its contents
  // (`carry`), or taking what is there already (an online change moved the
  // cells). The built-in blocks' pins follow. Scan path: no allocation.
  void relocate(Cell* to, bool carry) noexcept;
  std::uint32_t frame_cells() const noexcept { return module_->pous[pou_].frame_cells; }
  const CompiledPou& pou() const noexcept { return module_->pous[pou_]; }
  const Module& module() const noexcept { return *module_; }
  const char* stopped() const noexcept { return vm_.stopped; }
  std::uint64_t faults() const noexcept { return vm_.faults; }
  const char* last_fault() const noexcept { return vm_.last_fault; }
  // Binds VAR_EXTERNAL `name` of the instance's POU to a cell outside (a tag).
  bool bind_external(std::string_view name, Cell* cell) noexcept;
  // The block instances its AXIS_REFs name (Vm::targets): `n` of them,
  // sized at load; set_target runs between scans (StBlock::link).
  void set_target_count(std::uint32_t n) {
    targets_.assign(n, nullptr);
    vm_.targets = targets_.data();
    vm_.target_count = n;
  }
  void set_target(std::uint32_t k, Block* target) noexcept {
    if (k < targets_.size()) targets_[k] = target;
  }
  // Every VAR_EXTERNAL reference cell of the frame, nested FB instances' too:
  // (cell, name), for the owner to bind.
  const std::vector<std::pair<std::uint32_t, std::string>>& externals() const noexcept { return externals_; }

 private:
  void create_blocks(std::uint32_t pou, std::uint32_t at, const InstanceSetup& setup, const std::string& path);
  void find_externals(std::uint32_t pou, std::uint32_t at);

  std::shared_ptr<const Module> module_;
  std::uint32_t pou_ = 0;
  const CompiledPou* compiled_ = nullptr;  // module_->pous[pou_]: the module never changes
  std::vector<Cell> area_;  // the frame until relocated, the FUNCTIONs' frames, scratch
  Cell* frame_ = nullptr;
  std::vector<std::uint32_t> block_at_;
  std::vector<const BlockSlot*> slots_;  // each built-in block's slot (its pins' layout)
  std::vector<std::unique_ptr<Block>> blocks_;
  std::vector<std::unique_ptr<Cell*[]>> pins_;
  std::vector<std::pair<std::uint32_t, std::string>> externals_;
  std::vector<Block*> targets_;
  Vm vm_;
};

}  // namespace syncplc::st::vm
