// IEC 61131-3 selection functions LIMIT, MAX, MIN (extensible), SEL, MOVE
// over ANY.
#include <cmath>

#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

template <class V>
V max_of(V a, V b) noexcept {
  if constexpr (std::is_floating_point_v<V>) return std::fmax(a, b);  // inputs are finite (finite_guard.hpp)
  else return b > a ? b : a;
}
template <class V>
V min_of(V a, V b) noexcept {
  if constexpr (std::is_floating_point_v<V>) return std::fmin(a, b);
  else return b < a ? b : a;
}

struct MaxOp {
  template <class V>
  static V apply(V a, V b) noexcept { return max_of(a, b); }
};
struct MinOp {
  template <class V>
  static V apply(V a, V b) noexcept { return min_of(a, b); }
};
template <IecType T>
using MaxBlock = FoldBlock<T, MaxOp>;
template <IecType T>
using MinBlock = FoldBlock<T, MinOp>;

template <IecType T>
class LimitBlock final : public Block {
  using V = native_t<T>;
  enum : int { kMn = 0, kIn = 1, kMx = 2, kOut = 3 };

 public:
  explicit LimitBlock(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    const V mn = in<V>(kMn);
    const V mx = in<V>(kMx);
    V v = in<V>(kIn);
    if (v < mn) v = mn;
    if (v > mx) v = mx;
    out<V>(kOut, v);
  }
};

// SEL and MOVE copy whole cells: the same code serves every type.
class SelBlock final : public Block {
  enum : int { kG = 0, kIn0 = 1, kIn1 = 2, kOut = 3 };

 public:
  void execute(ScanContext&) noexcept override { *pin_cell(kOut) = *pin_cell(in<bool>(kG) ? kIn1 : kIn0); }
};

class MoveBlock final : public Block {
 public:
  void execute(ScanContext&) noexcept override { *pin_cell(1) = *pin_cell(0); }
};

BlockTypeInfo sel_info(const char* name, std::string doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC selection";
  t.doc = std::move(doc);
  t.reference = kRefFn;
  t.default_datatype = IecType::LREAL;
  return t;
}

}  // namespace

void register_selection(BlockRegistry& r) {
  constexpr auto C = TypeClass::ANY;
  {
    auto t = sel_info("MAX",
                      "Maximum OUT := MAX(IN1, IN2, ...) over ANY (default LREAL; BOOL: FALSE < TRUE). "
                      "Extensible: IN1 and IN2 are required, IN3..IN8 take part only when connected. For reals "
                      "A NaN or infinite input holds OUT (the finite-input rule, see ENO).");
    add_extensible_pins(t, C, "compared");
    t.pins.push_back(output("OUT", C).doc("largest input"));
    t.create = make_generic<C, MaxBlock>;
    r.add(std::move(t));
  }
  {
    auto t = sel_info("MIN",
                      "Minimum OUT := MIN(IN1, IN2, ...) over ANY (default LREAL; BOOL: FALSE < TRUE). "
                      "Extensible: IN1 and IN2 are required, IN3..IN8 take part only when connected. For reals "
                      "A NaN or infinite input holds OUT (the finite-input rule, see ENO).");
    add_extensible_pins(t, C, "compared");
    t.pins.push_back(output("OUT", C).doc("smallest input"));
    t.create = make_generic<C, MinBlock>;
    r.add(std::move(t));
  }
  {
    auto t = sel_info("LIMIT",
                      "Limiter OUT := MIN(MAX(IN, MN), MX) over ANY (default LREAL). If MN > MX the result is "
                      "MX. A NaN or infinite input holds OUT (the finite-input rule, see ENO).");
    t.pins = {input("MN", C).doc("lower limit"), input("IN", C).required().doc("value to limit"),
              input("MX", C).doc("upper limit"), output("OUT", C).doc("IN limited to [MN, MX]")};
    t.create = make_generic<C, LimitBlock>;
    r.add(std::move(t));
  }
  {
    auto t = sel_info("SEL", "Binary selection OUT := IN0 if G is FALSE, IN1 if G is TRUE, over ANY (default LREAL).");
    t.pins = {input("G", IecType::BOOL).required().doc("selector: FALSE picks IN0, TRUE picks IN1"),
              input("IN0", C).doc("value when G is FALSE"), input("IN1", C).doc("value when G is TRUE"),
              output("OUT", C).doc("selected input")};
    t.create = make_plain<SelBlock>();
    r.add(std::move(t));
  }
  {
    auto t = sel_info("MOVE", "Assignment OUT := IN over ANY (default LREAL).");
    t.pins = {input("IN", C).required().doc("value to copy"), output("OUT", C).doc("copy of IN")};
    t.create = make_plain<MoveBlock>();
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
