// IEC 61131-3 edge detection: R_TRIG, F_TRIG.
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kClk = 0, kTrigQ = 1 };

class RTrig final : public Block {
 public:
  void execute(ScanContext&) noexcept override {
    const bool clk = in<bool>(kClk);
    out<bool>(kTrigQ, clk && !m_);
    m_ = clk;
  }

 private:
  bool m_ = false;  // CLK of the previous scan; starts as "CLK was FALSE"
};

class FTrig final : public Block {
 public:
  void execute(ScanContext&) noexcept override {
    const bool clk = in<bool>(kClk);
    out<bool>(kTrigQ, !clk && m_);
    m_ = clk;
  }

 private:
  bool m_ = false;  // CLK of the previous scan; starts as "CLK was FALSE"
};

BlockTypeInfo edge_info(const char* name, std::string doc, std::string q_doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC edge detection";
  t.doc = std::move(doc);
  t.reference = kRefFB;
  t.pins = {
      input("CLK", IecType::BOOL).doc("signal whose edges are detected"),
      output("Q", IecType::BOOL).doc(std::move(q_doc)),
  };
  return t;
}

}  // namespace

void register_edges(BlockRegistry& r) {
  {
    auto t = edge_info("R_TRIG",
                       "Rising-edge detector: Q := CLK AND NOT M; M := CLK, so Q is TRUE for exactly one scan "
                       "after CLK goes from FALSE to TRUE. M starts FALSE (\"CLK was FALSE\"), so Q is TRUE on "
                       "the first scan if CLK is already TRUE.",
                       "TRUE for one scan on each rising edge of CLK");
    t.create = make_plain<RTrig>();
    r.add(std::move(t));
  }
  {
    auto t = edge_info("F_TRIG",
                       "Falling-edge detector: Q := NOT CLK AND M; M := CLK, so Q is TRUE for exactly one scan "
                       "after CLK goes from TRUE to FALSE. M starts as \"CLK was FALSE\", so there is never a "
                       "pulse on the first scan (the spurious first-scan pulse that the IEC reference text can "
                       "give, depending on how its memory variable is initialised, is avoided).",
                       "TRUE for one scan on each falling edge of CLK");
    t.create = make_plain<FTrig>();
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
