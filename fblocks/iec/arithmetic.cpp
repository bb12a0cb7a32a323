// IEC 61131-3 arithmetic functions ADD, MUL (extensible), SUB, DIV, MOD, ABS.
// Integers (and TIME, nanoseconds in an int64) wrap in two's complement: the
// computation is done in the unsigned type, so overflow is never undefined.
// Reals follow IEEE 754 in the instance's precision (REAL: float, LREAL: double).
#include <cmath>

#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kIn1 = 0, kIn2 = 1, kOut = 2 };

struct AddOp {
  template <class V>
  static V apply(V a, V b) noexcept { return wrap_add(a, b); }
};
struct MulOp {
  template <class V>
  static V apply(V a, V b) noexcept { return wrap_mul(a, b); }
};
template <IecType T>
using AddBlock = FoldBlock<T, AddOp>;
template <IecType T>
using MulBlock = FoldBlock<T, MulOp>;

template <IecType T>
class SubBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit SubBlock(BlockSetup&) {}
  void execute(ScanContext&) noexcept override { out<V>(kOut, wrap_sub(in<V>(kIn1), in<V>(kIn2))); }
};

template <IecType T>
class DivBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit DivBlock(BlockSetup&) {}
  void execute(ScanContext& ctx) noexcept override {
    const V a = in<V>(kIn1);
    const V b = in<V>(kIn2);
    V r;
    if constexpr (std::is_floating_point_v<V>) {
      r = a / b;  // IEEE: +-inf or NaN on division by zero
    } else {
      if (b == 0) {
        r = 0;
        ctx.fault("DIV: division by zero", static_cast<double>(a));
      } else if (std::is_signed_v<V> && b == static_cast<V>(-1)) {
        r = wrap_neg(a);  // MIN / -1 = MIN, no trap
      } else {
        r = static_cast<V>(a / b);  // truncates toward zero
      }
    }
    out<V>(kOut, r);
  }
};

template <IecType T>
class ModBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit ModBlock(BlockSetup&) {}
  void execute(ScanContext& ctx) noexcept override {
    const V a = in<V>(kIn1);
    const V b = in<V>(kIn2);
    V r;
    if (b == 0) {
      r = 0;
      ctx.fault("MOD: division by zero", static_cast<double>(a));
    } else if (std::is_signed_v<V> && b == static_cast<V>(-1)) {
      r = 0;  // MIN MOD -1 would trap in hardware
    } else {
      r = static_cast<V>(a % b);  // sign of IN1
    }
    out<V>(kOut, r);
  }
};

template <IecType T>
class AbsBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit AbsBlock(BlockSetup&) {}
  void execute(ScanContext&) noexcept override {
    const V a = in<V>(0);
    V r;
    if constexpr (std::is_floating_point_v<V>) r = std::fabs(a);
    else if constexpr (std::is_signed_v<V>) r = a < 0 ? wrap_neg(a) : a;
    else r = a;
    out<V>(1, r);
  }
};

BlockTypeInfo arith_info(const char* name, std::string doc) {
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC arithmetic";
  t.doc = std::move(doc);
  t.reference = kRefFn;
  t.default_datatype = IecType::LREAL;
  return t;
}

void binary_pins(BlockTypeInfo& t, TypeClass c, std::string in1, std::string in2, std::string out) {
  t.pins = {input("IN1", c).required().doc(std::move(in1)), input("IN2", c).required().doc(std::move(in2)),
            output("OUT", c).doc(std::move(out))};
}

}  // namespace

void register_arithmetic(BlockRegistry& r) {
  {
    constexpr auto C = TypeClass::ANY_MAGNITUDE;
    auto t = arith_info("ADD",
                        "Sum OUT := IN1 + IN2 + ... over ANY_MAGNITUDE (default LREAL; TIME adds durations). "
                        "Extensible: IN1 and IN2 are required, IN3..IN8 are added only when connected. "
                        "Integers and TIME wrap around in two's complement; reals follow IEEE 754.");
    add_extensible_pins(t, C, "added");
    t.pins.push_back(output("OUT", C).doc("sum"));
    t.create = make_generic<C, AddBlock>;
    r.add(std::move(t));
  }
  {
    constexpr auto C = TypeClass::ANY_MAGNITUDE;
    auto t = arith_info("SUB",
                        "Difference OUT := IN1 - IN2 over ANY_MAGNITUDE (default LREAL; TIME subtracts "
                        "durations). Integers and TIME wrap around in two's complement (unsigned 0 - 1 gives "
                        "the maximum); reals follow IEEE 754.");
    binary_pins(t, C, "minuend", "subtrahend", "IN1 - IN2");
    t.create = make_generic<C, SubBlock>;
    r.add(std::move(t));
  }
  {
    constexpr auto C = TypeClass::ANY_NUM;
    auto t = arith_info("MUL",
                        "Product OUT := IN1 * IN2 * ... over ANY_NUM (default LREAL). Extensible: IN1 and IN2 "
                        "are required, IN3..IN8 are multiplied in only when connected. Integers wrap around "
                        "in two's complement (the low bits of the exact product); reals follow IEEE 754.");
    add_extensible_pins(t, C, "multiplied in");
    t.pins.push_back(output("OUT", C).doc("product"));
    t.create = make_generic<C, MulBlock>;
    r.add(std::move(t));
  }
  {
    constexpr auto C = TypeClass::ANY_NUM;
    auto t = arith_info("DIV",
                        "Quotient OUT := IN1 / IN2 over ANY_NUM (default LREAL). Integers truncate toward "
                        "zero. Integer division by zero gives OUT := 0 and raises a block-fault event "
                        "\"DIV: division by zero\" (the task reports it once per series of faulting scans); the signed minimum divided by -1 "
                        "gives the minimum (wrap-around, no trap). Reals follow IEEE 754 (x/0 gives +-inf, "
                        "0/0 NaN, no event; a block that reads such a value holds its outputs with ENO FALSE).");
    binary_pins(t, C, "dividend", "divisor", "IN1 / IN2");
    t.create = make_generic<C, DivBlock>;
    r.add(std::move(t));
  }
  {
    constexpr auto C = TypeClass::ANY_INT;
    auto t = arith_info("MOD",
                        "Remainder OUT := IN1 - (IN1 / IN2) * IN2 over ANY_INT (default INT), with truncating "
                        "division, so the result has the sign of IN1 (-7 MOD 2 = -1). IN2 = 0 gives OUT := 0 "
                        "and raises a block-fault event \"MOD: division by zero\" (the task reports it once per series of faulting scans); "
                        "IN2 = -1 gives 0.");
    t.default_datatype = IecType::INT;
    binary_pins(t, C, "dividend", "divisor", "remainder, with the sign of IN1");
    t.create = make_generic<C, ModBlock>;
    r.add(std::move(t));
  }
  {
    constexpr auto C = TypeClass::ANY_NUM;
    auto t = arith_info("ABS",
                        "Absolute value OUT := |IN| over ANY_NUM (default LREAL). Unsigned types are returned "
                        "unchanged; the signed minimum (e.g. INT -32768) has no positive counterpart and is "
                        "returned unchanged (two's complement wrap-around). ABS(-0.0) = 0.0. A NaN or infinite IN is the finite-input rule's (see ENO): OUT holds.");
    t.pins = {input("IN", C).required().doc("operand"), output("OUT", C).doc("absolute value of IN")};
    t.create = make_generic<C, AbsBlock>;
    r.add(std::move(t));
  }
}

}  // namespace syncplc::iec
