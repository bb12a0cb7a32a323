// IEC 61131-3 counters CTU, CTD, CTUD, generic over ANY_INT: PV and CV take
// the instance's type (default INT), so CTU with datatype DINT is CTU_DINT.
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

template <IecType T>
class Ctu final : public Block {
  using V = native_t<T>;
  enum : int { kCu = 0, kR = 1, kPv = 2, kQ = 3, kCv = 4 };

 public:
  explicit Ctu(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    const bool cu = in<bool>(kCu);
    const bool edge = cu && !cu_m_;
    cu_m_ = cu;
    if (in<bool>(kR)) cv_ = 0;
    else if (edge && cv_ < std::numeric_limits<V>::max()) cv_ = static_cast<V>(cv_ + 1);
    out<bool>(kQ, cv_ >= in<V>(kPv));
    out<V>(kCv, cv_);
  }

 // Retained: the count and the edge memory (a restart with CU still TRUE is no new edge).
  std::uint32_t retain_cells() const noexcept override { return 2; }
  void save_retain(Cell* out) const noexcept override { out[0].set<V>(cv_); out[1].set<bool>(cu_m_); }
  void load_retain(const Cell* in) noexcept override { cv_ = in[0].get<V>(); cu_m_ = in[1].get<bool>(); }

 private:
  bool cu_m_ = false;
  V cv_ = 0;
};

template <IecType T>
class Ctd final : public Block {
  using V = native_t<T>;
  enum : int { kCd = 0, kLd = 1, kPv = 2, kQ = 3, kCv = 4 };

 public:
  explicit Ctd(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    const bool cd = in<bool>(kCd);
    const bool edge = cd && !cd_m_;
    cd_m_ = cd;
    if (in<bool>(kLd)) cv_ = in<V>(kPv);
    else if (edge && cv_ > std::numeric_limits<V>::min()) cv_ = static_cast<V>(cv_ - 1);
    out<bool>(kQ, cv_ <= 0);
    out<V>(kCv, cv_);
  }

 std::uint32_t retain_cells() const noexcept override { return 2; }
  void save_retain(Cell* out) const noexcept override { out[0].set<V>(cv_); out[1].set<bool>(cd_m_); }
  void load_retain(const Cell* in) noexcept override { cv_ = in[0].get<V>(); cd_m_ = in[1].get<bool>(); }

 private:
  bool cd_m_ = false;
  V cv_ = 0;
};

template <IecType T>
class Ctud final : public Block {
  using V = native_t<T>;
  enum : int { kCu = 0, kCd = 1, kR = 2, kLd = 3, kPv = 4, kQu = 5, kQd = 6, kCv = 7 };

 public:
  explicit Ctud(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    const bool cu = in<bool>(kCu);
    const bool cd = in<bool>(kCd);
    const bool up = cu && !cu_m_;
    const bool down = cd && !cd_m_;
    cu_m_ = cu;
    cd_m_ = cd;
    const V pv = in<V>(kPv);
    if (in<bool>(kR)) {
      cv_ = 0;
    } else if (in<bool>(kLd)) {
      cv_ = pv;
    } else if (up != down) {
      if (up && cv_ < std::numeric_limits<V>::max()) cv_ = static_cast<V>(cv_ + 1);
      else if (down && cv_ > std::numeric_limits<V>::min()) cv_ = static_cast<V>(cv_ - 1);
    }
    out<bool>(kQu, cv_ >= pv);
    out<bool>(kQd, cv_ <= 0);
    out<V>(kCv, cv_);
  }

 std::uint32_t retain_cells() const noexcept override { return 3; }
  void save_retain(Cell* out) const noexcept override {
    out[0].set<V>(cv_);
    out[1].set<bool>(cu_m_);
    out[2].set<bool>(cd_m_);
  }
  void load_retain(const Cell* in) noexcept override {
    cv_ = in[0].get<V>();
    cu_m_ = in[1].get<bool>();
    cd_m_ = in[2].get<bool>();
  }

 private:
  bool cu_m_ = false;
  bool cd_m_ = false;
  V cv_ = 0;
};

BlockTypeInfo counter_info(const char* name, std::string doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC counters";
  t.doc = std::move(doc);
  t.reference = kRefFB;
  t.default_datatype = IecType::INT;
  return t;
}

}  // namespace

void register_counters(BlockRegistry& r) {
  constexpr auto C = TypeClass::ANY_INT;
  {
    auto t = counter_info(
        "CTU",
        "Up counter over ANY_INT (default INT). Each rising edge of CU (edge memory starts FALSE, so CU TRUE "
        "on the first scan counts) adds 1 to CV unless CV is at the maximum of the type (no wrap-around). "
        "R TRUE sets CV := 0 and blocks counting. Q := CV >= PV. CV starts at 0.");
    t.pins = {
        input("CU", IecType::BOOL).doc("count up on each rising edge"),
        input("R", IecType::BOOL).doc("reset CV to 0 (while TRUE, edges are not counted)"),
        input("PV", C).doc("preset value; Q when CV reaches it"),
        output("Q", IecType::BOOL).doc("CV >= PV"),
        output("CV", C).doc("current count"),
    };
    t.create = make_generic<C, Ctu>;
    r.add(std::move(t));
  }
  {
    auto t = counter_info(
        "CTD",
        "Down counter over ANY_INT (default INT). LD TRUE loads CV := PV (and blocks counting); otherwise each "
        "rising edge of CD (edge memory starts FALSE) subtracts 1 from CV unless CV is at the minimum of the "
        "type (no wrap-around; 0 for unsigned types). Q := CV <= 0. CV starts at 0.");
    t.pins = {
        input("CD", IecType::BOOL).doc("count down on each rising edge"),
        input("LD", IecType::BOOL).doc("load PV into CV (while TRUE, edges are not counted)"),
        input("PV", C).doc("value loaded by LD"),
        output("Q", IecType::BOOL).doc("CV <= 0"),
        output("CV", C).doc("current count"),
    };
    t.create = make_generic<C, Ctd>;
    r.add(std::move(t));
  }
  {
    auto t = counter_info(
        "CTUD",
        "Up/down counter over ANY_INT (default INT). Priority: R (CV := 0) over LD (CV := PV) over counting. "
        "Otherwise a rising edge of CU adds 1 (not past the type's maximum) and a rising edge of CD subtracts "
        "1 (not below the type's minimum); rising edges of CU and CD in the same scan cancel. Edge memories "
        "start FALSE and are updated every scan, also while R or LD is TRUE. QU := CV >= PV; QD := CV <= 0. "
        "CV starts at 0.");
    t.pins = {
        input("CU", IecType::BOOL).doc("count up on each rising edge"),
        input("CD", IecType::BOOL).doc("count down on each rising edge"),
        input("R", IecType::BOOL).doc("reset CV to 0 (dominant over LD)"),
        input("LD", IecType::BOOL).doc("load PV into CV"),
        input("PV", C).doc("preset value: QU threshold and value loaded by LD"),
        output("QU", IecType::BOOL).doc("CV >= PV"),
        output("QD", IecType::BOOL).doc("CV <= 0"),
        output("CV", C).doc("current count"),
    };
    t.create = make_generic<C, Ctud>;
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
