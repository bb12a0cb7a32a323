// IEC 61131-3 bit-string functions AND, OR, XOR (extensible) and NOT over
// ANY_BIT: logical for BOOL, bitwise for BYTE, WORD, DWORD, LWORD.
#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

struct AndOp {
  template <class V>
  static V apply(V a, V b) noexcept {
    if constexpr (std::is_same_v<V, bool>) return a && b;
    else return static_cast<V>(a & b);
  }
};
struct OrOp {
  template <class V>
  static V apply(V a, V b) noexcept {
    if constexpr (std::is_same_v<V, bool>) return a || b;
    else return static_cast<V>(a | b);
  }
};
struct XorOp {
  template <class V>
  static V apply(V a, V b) noexcept {
    if constexpr (std::is_same_v<V, bool>) return a != b;
    else return static_cast<V>(a ^ b);
  }
};
template <IecType T>
using AndBlock = FoldBlock<T, AndOp>;
template <IecType T>
using OrBlock = FoldBlock<T, OrOp>;
template <IecType T>
using XorBlock = FoldBlock<T, XorOp>;

template <IecType T>
class NotBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit NotBlock(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    if constexpr (std::is_same_v<V, bool>) out<bool>(1, !in<bool>(0));
    else out<V>(1, static_cast<V>(~in<V>(0)));
  }
};

BlockTypeInfo logic_info(const char* name, std::string doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC bit logic";
  t.doc = std::move(doc);
  t.reference = kRefFn;
  t.default_datatype = IecType::BOOL;
  return t;
}

}  // namespace

void register_logic(BlockRegistry& r) {
  constexpr auto C = TypeClass::ANY_BIT;
  {
    auto t = logic_info("AND",
                        "OUT := IN1 AND IN2 AND ... over ANY_BIT (default BOOL): logical for BOOL, bitwise for "
                        "BYTE, WORD, DWORD, LWORD. Extensible: IN1 and IN2 are required, IN3..IN8 take part "
                        "only when connected.");
    add_extensible_pins(t, C, "ANDed in");
    t.pins.push_back(output("OUT", C).doc("conjunction of the inputs"));
    t.create = make_generic<C, AndBlock>;
    r.add(std::move(t));
  }
  {
    auto t = logic_info("OR",
                        "OUT := IN1 OR IN2 OR ... over ANY_BIT (default BOOL): logical for BOOL, bitwise for "
                        "BYTE, WORD, DWORD, LWORD. Extensible: IN1 and IN2 are required, IN3..IN8 take part "
                        "only when connected.");
    add_extensible_pins(t, C, "ORed in");
    t.pins.push_back(output("OUT", C).doc("disjunction of the inputs"));
    t.create = make_generic<C, OrBlock>;
    r.add(std::move(t));
  }
  {
    auto t = logic_info("XOR",
                        "OUT := IN1 XOR IN2 XOR ... over ANY_BIT (default BOOL): logical for BOOL, bitwise for "
                        "BYTE, WORD, DWORD, LWORD. With more than two inputs it is the chained XOR, i.e. the "
                        "parity (TRUE when an odd number of inputs is TRUE), not \"exactly one\". Extensible: "
                        "IN1 and IN2 are required, IN3..IN8 take part only when connected.");
    add_extensible_pins(t, C, "XORed in");
    t.pins.push_back(output("OUT", C).doc("exclusive or (parity) of the inputs"));
    t.create = make_generic<C, XorBlock>;
    r.add(std::move(t));
  }
  {
    auto t = logic_info("NOT",
                        "OUT := NOT IN over ANY_BIT (default BOOL): logical negation for BOOL, bitwise "
                        "complement for BYTE, WORD, DWORD, LWORD.");
    t.pins = {input("IN", C).required().doc("operand"), output("OUT", C).doc("negation of IN")};
    t.create = make_generic<C, NotBlock>;
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
