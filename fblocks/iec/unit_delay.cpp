// UNIT_DELAY: the one-scan delay that lets a feedback loop through the
// project's dependency check. Not an IEC 61131-3 standard block.
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kDelayIn = 0, kDelayOut = 1 };

// Copies whole cells, so one implementation serves every type; the initial
// all-zero cell is the zero of every type (FALSE, 0, 0.0, T#0s).
class UnitDelay final : public Block {
 public:
  void execute(ScanContext&) noexcept override { *pin_cell(kDelayOut) = state_; }
  void end_of_scan() noexcept override { state_ = *pin_cell(kDelayIn); }
  // The sample survives a restart: a loop through the delay goes on from it.
  std::uint32_t retain_cells() const noexcept override { return 1; }
  void save_retain(Cell* out) const noexcept override { out[0] = state_; }
  void load_retain(const Cell* in) noexcept override { state_ = in[0]; }

 private:
  Cell state_{};
};

}  // namespace

void register_unit_delay(BlockRegistry& r) {
  constexpr auto C = TypeClass::ANY;
  BlockTypeInfo t;
  t.name = "UNIT_DELAY";
  t.category = "execution control";
  t.doc = "One-scan delay over ANY (default LREAL): OUT is the value IN had at the end of the previous scan "
          "(the type's zero on the first scan). OUT is written when the block executes and IN is sampled "
          "after every block of the task has executed, so OUT does not depend on this scan's inputs and a "
          "connection loop through UNIT_DELAY is allowed.";
  t.reference = "syncplc execution control block (z^-1 unit delay; not an IEC 61131-3 standard block)";
  t.default_datatype = IecType::LREAL;
  t.unit_delay = true;
  t.pins = {input("IN", C).required().doc("value sampled at the end of the scan"),
            output("OUT", C).doc("IN of the previous scan; the type's zero on the first scan")};
  t.create = make_plain<UnitDelay>();
  r.add(std::move(t));
}

}  // namespace syncplc::iec
