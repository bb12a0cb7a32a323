// Internal helpers shared by the IEC 61131-3 block families in fblocks/iec.
// Not part of the public block interface.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>

#include "runtime/core/block.hpp"
#include "runtime/core/pin_decl.hpp"

namespace syncplc::iec {

// One registration function per family (each in its own .cpp).
void register_timers(BlockRegistry& r);
void register_edges(BlockRegistry& r);
void register_counters(BlockRegistry& r);
void register_bistables(BlockRegistry& r);
void register_arithmetic(BlockRegistry& r);
void register_comparison(BlockRegistry& r);
void register_selection(BlockRegistry& r);
void register_logic(BlockRegistry& r);
void register_unit_delay(BlockRegistry& r);
void register_burn(BlockRegistry& r);
void register_conversions(BlockRegistry& r);  // *_TO_**, *_TRUNC_** (conversion.cpp)

inline constexpr const char* kRefFB = "IEC 61131-3 standard function block";
inline constexpr const char* kRefFn = "IEC 61131-3 standard function";

template <IecType T>
using native_t = typename Native<T>::type;

// Compile-time twin of in_class(), so a generic block is only instantiated for
// the types its class admits.
constexpr bool type_in_class(IecType t, TypeClass c) {
  const bool sint = t == IecType::SINT || t == IecType::INT || t == IecType::DINT || t == IecType::LINT;
  const bool uint = t == IecType::USINT || t == IecType::UINT || t == IecType::UDINT || t == IecType::ULINT;
  const bool real = t == IecType::REAL || t == IecType::LREAL;
  const bool bits = t == IecType::BOOL || t == IecType::BYTE || t == IecType::WORD || t == IecType::DWORD ||
                    t == IecType::LWORD;
  switch (c) {
    case TypeClass::Exact: return false;
    case TypeClass::ANY: return true;
    case TypeClass::ANY_MAGNITUDE: return sint || uint || real || t == IecType::TIME;
    case TypeClass::ANY_NUM: return sint || uint || real;
    case TypeClass::ANY_INT: return sint || uint;
    case TypeClass::ANY_REAL: return real;
    case TypeClass::ANY_BIT: return bits;
  }
  return false;
}

// Instantiates Impl<T> for the instance's resolved generic type, which must
// belong to class C. Impl<T> is constructed from the BlockSetup.
template <TypeClass C, template <IecType> class Impl>
std::unique_ptr<Block> make_generic(BlockSetup& s) {
  const IecType t = s.datatype();
  if (!type_in_class(t, C)) {
    s.error(s.type().name + ": data type " + std::string(type_name(t)) + " is not " +
            std::string(class_name(C)));
    return nullptr;
  }
  return dispatch_type(t, [&]<IecType T>() -> std::unique_ptr<Block> {
    if constexpr (type_in_class(T, C)) return std::make_unique<Impl<T>>(s);
    else return nullptr;
  });
}

// Factory for a block type with no generic pins and a default constructor.
template <class B>
BlockFactory make_plain() {
  return [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<B>(); };
}

// Extensible functions (ADD, MUL, MAX, MIN, AND, OR, XOR) declare IN1..IN8 then
// OUT. IN1 and IN2 are required; IN3..IN8 take part only when connected.
inline constexpr int kMaxInputs = 8;
inline constexpr int kExtOut = kMaxInputs;  // pin index of OUT

inline void add_extensible_pins(BlockTypeInfo& info, TypeClass cls, const std::string& what) {
  info.rewire = true;  // FoldBlock::rewire_from: an operand wired in or out by an online change takes part at once
  for (int i = 1; i <= kMaxInputs; ++i) {
    const bool req = i <= 2;
    info.pins.push_back(input("IN" + std::to_string(i), cls)
                            .required(req)
                            .doc(req ? "operand " + std::to_string(i)
                                     : "optional operand " + std::to_string(i) + "; " + what + " only when connected"));
  }
}

// The input pins of an extensible instance that take part: IN1, IN2 and the
// connected ones among IN3..IN8, in order.
struct ExtInputs {
  int idx[kMaxInputs] = {};
  int count = 0;
  explicit ExtInputs(const BlockSetup& s) {
    for (int i = 0; i < kMaxInputs; ++i)
      if (i < 2 || s.connected(i)) idx[count++] = i;
  }
};

// An extensible function folded left over its taking-part inputs:
// OUT := Op(...Op(Op(IN1, IN2), INk)...). Op::apply<V>(a, b) must be noexcept.
template <IecType T, class Op>
class FoldBlock final : public Block {
  using V = native_t<T>;

 public:
  explicit FoldBlock(BlockSetup& s) : ins_(s) {}
  void rewire_from(const Block& fresh) noexcept override { ins_ = static_cast<const FoldBlock&>(fresh).ins_; }
  void execute(ScanContext&) noexcept override {
    V acc = in<V>(ins_.idx[0]);
    for (int k = 1; k < ins_.count; ++k) acc = Op::apply(acc, in<V>(ins_.idx[k]));
    out<V>(kExtOut, acc);
  }

 private:
  ExtInputs ins_;
};

// ---- integer arithmetic without undefined behaviour ------------------------

// The unsigned type in which T is computed: at least `unsigned int`, so that
// narrow operands are not promoted to (signed) int before multiplying.
template <class T>
using wide_unsigned_t =
    std::conditional_t<(sizeof(T) < sizeof(unsigned)), unsigned, std::make_unsigned_t<T>>;

template <class T>
constexpr T wrap_add(T a, T b) noexcept {
  if constexpr (std::is_integral_v<T>) {
    using U = wide_unsigned_t<T>;
    return static_cast<T>(static_cast<U>(static_cast<U>(a) + static_cast<U>(b)));
  } else {
    return a + b;
  }
}

template <class T>
constexpr T wrap_sub(T a, T b) noexcept {
  if constexpr (std::is_integral_v<T>) {
    using U = wide_unsigned_t<T>;
    return static_cast<T>(static_cast<U>(static_cast<U>(a) - static_cast<U>(b)));
  } else {
    return a - b;
  }
}

template <class T>
constexpr T wrap_mul(T a, T b) noexcept {
  if constexpr (std::is_integral_v<T>) {
    using U = wide_unsigned_t<T>;
    return static_cast<T>(static_cast<U>(static_cast<U>(a) * static_cast<U>(b)));
  } else {
    return a * b;
  }
}

template <class T>
constexpr T wrap_neg(T a) noexcept {
  return wrap_sub<T>(T{0}, a);
}

// Time elapsed from `start` to `now`, never negative, saturating instead of
// overflowing.
inline std::int64_t elapsed_ns(std::int64_t now, std::int64_t start) noexcept {
  std::int64_t d;
  if (__builtin_sub_overflow(now, start, &d)) return now > start ? std::numeric_limits<std::int64_t>::max() : 0;
  return d < 0 ? 0 : d;
}

}  // namespace syncplc::iec
