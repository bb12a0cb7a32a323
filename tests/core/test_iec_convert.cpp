// conversion_fn (runtime/core/iec_convert.hpp): the table the ST VM resolves
// a conversion from, beside the conversion blocks' tests (tests/iec): the
// identity, TRUNC against nearest, what only the VM can feed it (NaN,
// infinity), and that every entry is the conversion of its own pair.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "runtime/core/iec_convert.hpp"

namespace syncplc {
namespace {

template <class T>
Cell cell_of(T v) {
  Cell c;
  c.set<T>(v);
  return c;
}

template <class D, class S>
D conv(IecType s, IecType d, S in, bool trunc = false, bool* oor = nullptr) {
  bool flag = false;
  const Cell out = conversion_fn(s, d, trunc)(cell_of<S>(in), &flag);
  if (oor) *oor = flag;
  return out.get<D>();
}

TEST(IecConvert, SameTypeIsTheIdentity) {
  for (int i = 0; i < kIecTypeCount; ++i) {
    const auto t = static_cast<IecType>(i);
    Cell in;
    in.raw = 0x0123456789ABCDEFULL;
    bool oor = false;
    EXPECT_EQ(conversion_fn(t, t, false)(in, &oor).raw, in.raw) << type_name(t);
    EXPECT_EQ(conversion_fn(t, t, true)(in, &oor).raw, in.raw) << type_name(t);
    EXPECT_FALSE(oor);
  }
}

TEST(IecConvert, EveryEntryConvertsItsOwnPair) {
  // 1 in every type reads back as 1 (TRUE) in every other type: an entry
  // taken from the wrong row or column would misread or miswrite the width.
  const auto one = [](IecType t) {
    return dispatch_type(t, [&]<IecType T>() {
      using N = typename Native<T>::type;
      Cell c;
      if constexpr (T == IecType::TIME) c.set<N>(1'000'000);  // 1 ms
      else c.set<N>(static_cast<N>(1));
      return c;
    });
  };
  for (int i = 0; i < kIecTypeCount; ++i)
    for (int j = 0; j < kIecTypeCount; ++j) {
      const auto s = static_cast<IecType>(i), d = static_cast<IecType>(j);
      for (bool trunc : {false, true}) {
        bool oor = false;
        const Cell out = conversion_fn(s, d, trunc)(one(s), &oor);
        EXPECT_EQ(out.raw, one(d).raw) << type_name(s) << " -> " << type_name(d) << (trunc ? " trunc" : "");
        EXPECT_FALSE(oor);
      }
    }
}

TEST(IecConvert, TruncRoundsTowardZeroNearestToEven) {
  EXPECT_EQ(conv<std::int16_t>(IecType::REAL, IecType::INT, 2.5f), 2);
  EXPECT_EQ(conv<std::int16_t>(IecType::REAL, IecType::INT, 3.5f), 4);
  EXPECT_EQ(conv<std::int16_t>(IecType::REAL, IecType::INT, -2.7f, true), -2);
  EXPECT_EQ(conv<std::int16_t>(IecType::REAL, IecType::INT, 2.7f, true), 2);
  EXPECT_EQ(conv<std::uint8_t>(IecType::LREAL, IecType::BYTE, 254.9, true), 254);
  EXPECT_EQ(conv<std::uint8_t>(IecType::LREAL, IecType::BYTE, 254.9), 255);
  // TIME to an integer rounds its fraction of a millisecond the same way.
  EXPECT_EQ(conv<std::int32_t>(IecType::TIME, IecType::DINT, std::int64_t{1'700'000}), 2);
  EXPECT_EQ(conv<std::int32_t>(IecType::TIME, IecType::DINT, std::int64_t{1'700'000}, true), 1);
  // A real to TIME: whole nanoseconds, toward zero with trunc.
  EXPECT_EQ(conv<std::int64_t>(IecType::LREAL, IecType::TIME, 1.0000017), 1'000'002);
  EXPECT_EQ(conv<std::int64_t>(IecType::LREAL, IecType::TIME, 1.0000017, true), 1'000'001);
}

TEST(IecConvert, SaturatesAndReportsOutOfRange) {
  bool oor = false;
  EXPECT_EQ(conv<std::int8_t>(IecType::INT, IecType::SINT, std::int16_t{300}, false, &oor), 127);
  EXPECT_TRUE(oor);
  EXPECT_EQ(conv<std::uint16_t>(IecType::DINT, IecType::UINT, -1, false, &oor), 0);
  EXPECT_TRUE(oor);
  EXPECT_EQ(conv<std::uint16_t>(IecType::DINT, IecType::WORD, -1, false, &oor), 0xFFFF);  // bits: no fault
  EXPECT_FALSE(oor);
  EXPECT_EQ(conv<float>(IecType::LREAL, IecType::REAL, 1e300, false, &oor), std::numeric_limits<float>::max());
  EXPECT_TRUE(oor);
  EXPECT_EQ(conv<std::int64_t>(IecType::ULINT, IecType::TIME, std::numeric_limits<std::uint64_t>::max(), false, &oor),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_TRUE(oor);
  // out_of_range is only ever set: a later in-range conversion leaves it.
  bool sticky = true;
  (void)conversion_fn(IecType::INT, IecType::DINT, false)(cell_of<std::int16_t>(5), &sticky);
  EXPECT_TRUE(sticky);
}

// The blocks never see a NaN or an infinity (finite_guard.hpp); the VM can.
TEST(IecConvert, NanAndInfinityHaveDefinedResults) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  bool oor = false;
  EXPECT_EQ(conv<std::int32_t>(IecType::LREAL, IecType::DINT, nan, false, &oor), 0);
  EXPECT_TRUE(oor);
  oor = false;
  EXPECT_EQ(conv<std::uint64_t>(IecType::LREAL, IecType::LWORD, nan, true, &oor), 0u);
  EXPECT_TRUE(oor);
  oor = false;
  EXPECT_EQ(conv<std::int64_t>(IecType::LREAL, IecType::TIME, nan, false, &oor), 0);
  EXPECT_TRUE(oor);
  oor = false;
  EXPECT_TRUE(conv<bool>(IecType::LREAL, IecType::BOOL, nan, false, &oor));
  EXPECT_FALSE(oor);
  EXPECT_TRUE(std::isnan(conv<float>(IecType::LREAL, IecType::REAL, nan, false, &oor)));
  EXPECT_FALSE(oor);
  EXPECT_EQ(conv<std::int16_t>(IecType::LREAL, IecType::INT, -inf, false, &oor), -32768);
  EXPECT_TRUE(oor);
  oor = false;
  EXPECT_EQ(conv<std::int64_t>(IecType::REAL, IecType::TIME, std::numeric_limits<float>::infinity(), false, &oor),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_TRUE(oor);
}

TEST(IecConvert, AValueThatIsNoIecTypeGetsAnIdentity) {
  const ConvertFn f = conversion_fn(static_cast<IecType>(200), IecType::INT, false);
  ASSERT_NE(f, nullptr);
  bool oor = false;
  EXPECT_EQ(f(cell_of<std::int16_t>(-5), &oor).raw, cell_of<std::int16_t>(-5).raw);
}

}  // namespace
}  // namespace syncplc
