// IEC 61131-3 bistables: SR (set-dominant), RS (reset-dominant).
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kSet = 0, kReset = 1, kQ1 = 2 };

class Sr final : public Block {
 public:
  void execute(ScanContext&) noexcept override {
    q_ = in<bool>(kSet) || (!in<bool>(kReset) && q_);
    out<bool>(kQ1, q_);
  }

  // Retained: the latched Q1 (a latched alarm or a "homed" flag stays set over a restart).
  std::uint32_t retain_cells() const noexcept override { return 1; }
  void save_retain(Cell* out) const noexcept override { out[0].set<bool>(q_); }
  void load_retain(const Cell* in) noexcept override { q_ = in[0].get<bool>(); }

 private:
  bool q_ = false;
};

class Rs final : public Block {
 public:
  void execute(ScanContext&) noexcept override {
    q_ = !in<bool>(kReset) && (in<bool>(kSet) || q_);
    out<bool>(kQ1, q_);
  }

  // Retained: the latched Q1 (a latched alarm or a "homed" flag stays set over a restart).
  std::uint32_t retain_cells() const noexcept override { return 1; }
  void save_retain(Cell* out) const noexcept override { out[0].set<bool>(q_); }
  void load_retain(const Cell* in) noexcept override { q_ = in[0].get<bool>(); }

 private:
  bool q_ = false;
};

}  // namespace

void register_bistables(BlockRegistry& r) {
  {
    BlockTypeInfo t;
    t.name = "SR";
    t.category = "IEC bistables";
    t.doc = "Set-dominant bistable: Q1 := S1 OR (NOT R AND Q1). With S1 and R both TRUE, Q1 is TRUE. "
            "Q1 starts FALSE; a retain or persistent instance keeps Q1 over a restart.";
    t.reference = kRefFB;
    t.pins = {
        input("S1", IecType::BOOL).doc("set (dominant)"),
        input("R", IecType::BOOL).doc("reset"),
        output("Q1", IecType::BOOL).doc("stored state"),
    };
    t.create = make_plain<Sr>();
    r.add(std::move(t));
  }
  {
    BlockTypeInfo t;
    t.name = "RS";
    t.category = "IEC bistables";
    t.doc = "Reset-dominant bistable: Q1 := NOT R1 AND (S OR Q1). With S and R1 both TRUE, Q1 is FALSE. "
            "Q1 starts FALSE; a retain or persistent instance keeps Q1 over a restart.";
    t.reference = kRefFB;
    t.pins = {
        input("S", IecType::BOOL).doc("set"),
        input("R1", IecType::BOOL).doc("reset (dominant)"),
        output("Q1", IecType::BOOL).doc("stored state"),
    };
    t.create = make_plain<Rs>();
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
