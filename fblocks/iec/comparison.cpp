// IEC 61131-3 comparison functions GT, GE, EQ, NE, LE, LT over ANY: the two
// inputs take the instance's type, the output is BOOL.
#include <functional>

#include "fblocks/iec/common.hpp"

namespace syncplc::iec {
namespace {

enum : int { kCmpIn1 = 0, kCmpIn2 = 1, kCmpOut = 2 };

template <class Cmp>
struct CompareOf {
  template <IecType T>
  class Block final : public syncplc::Block {
    using V = native_t<T>;

   public:
    explicit Block(BlockSetup&) {}
    void execute(ScanContext&) noexcept override { out<bool>(kCmpOut, Cmp{}(in<V>(kCmpIn1), in<V>(kCmpIn2))); }
  };
};

template <class Cmp>
void add_compare(BlockRegistry& r, const char* name, const char* op, const char* what) {
  constexpr auto C = TypeClass::ANY;
  BlockTypeInfo t;
  t.name = name;
  t.category = "IEC comparison";
  t.doc = std::string("OUT := IN1 ") + op + " IN2 (" + what +
          ") over ANY (default LREAL); the output is BOOL. BOOL compares FALSE < TRUE; unsigned and "
          "bit-string types compare as unsigned numbers; TIME compares durations. A NaN or "
          "infinite input is the finite-input rule's (see ENO): the block does not execute and OUT holds.";
  t.reference = kRefFn;
  t.default_datatype = IecType::LREAL;
  t.pins = {input("IN1", C).required().doc("left operand"), input("IN2", C).required().doc("right operand"),
            output("OUT", IecType::BOOL).doc(std::string("IN1 ") + op + " IN2")};
  t.create = make_generic<C, CompareOf<Cmp>::template Block>;
  r.add(std::move(t));
}

}  // namespace

void register_comparison(BlockRegistry& r) {
  add_compare<std::greater<>>(r, "GT", ">", "greater than");
  add_compare<std::greater_equal<>>(r, "GE", ">=", "greater than or equal");
  add_compare<std::equal_to<>>(r, "EQ", "=", "equal");
  add_compare<std::not_equal_to<>>(r, "NE", "<>", "not equal");
  add_compare<std::less_equal<>>(r, "LE", "<=", "less than or equal");
  add_compare<std::less<>>(r, "LT", "<", "less than");
}

}  // namespace syncplc::iec
