// The VM's fixed-capacity strings (runtime/st/vm/st_string.*): the cell
// layout, every string function at its boundaries (empty strings, full
// capacity, truncation, L and P at 0, 1, LEN, LEN+1, negative and huge), the
// zeros after the length after every operation, STRING and WSTRING alike, and
// the conversions against format_value/parse_value (runtime/core/iec_type.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "runtime/core/iec_type.hpp"
#include "runtime/st/vm/st_string.hpp"

namespace syncplc::st::vm {
// A named namespace: test_st is a unity build.
namespace st_string_test {

constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

// A string variable of capacity n, its cells first filled with a pattern that
// every writing function must overwrite.
template <class C>
struct Var {
  explicit Var(int n) : cap(n), cells(static_cast<std::size_t>(string_cells_of<C>(n))) {
    for (auto& c : cells) c.raw = 0xA5A5A5A5A5A5A5A5ULL;
  }
  Cell* data() { return cells.data(); }
  const Cell* data() const { return cells.data(); }
  int cap;
  std::vector<Cell> cells;
};

template <class C>
std::basic_string<C> widen(const std::string& s) {
  return std::basic_string<C>(s.begin(), s.end());
}

// The characters of a string.
template <class C>
std::basic_string<C> text_of(const Cell* s) {
  std::basic_string<C> r(static_cast<std::size_t>(str_len(s)), C{});
  std::memcpy(r.data(), str_chars(s), r.size() * sizeof(C));
  return r;
}
template <class C>
std::string narrow(const Cell* s) {
  std::string r;
  for (C c : text_of<C>(s)) r.push_back(static_cast<char>(c));
  return r;
}

// The invariant: the length within the capacity, every character position
// from the length to the end of the cells zero.
template <class C>
::testing::AssertionResult invariant(const Var<C>& v) {
  const std::uint64_t len = v.cells[0].template get<std::uint64_t>();
  if (len > static_cast<std::uint64_t>(v.cap)) return ::testing::AssertionFailure() << "length " << len << " > capacity";
  const auto* b = reinterpret_cast<const unsigned char*>(v.data() + 1);
  const std::size_t all = (v.cells.size() - 1) * 8;
  for (std::size_t i = len * sizeof(C); i < all; ++i)
    if (b[i] != 0) return ::testing::AssertionFailure() << "byte " << i << " after the length is " << int(b[i]);
  return ::testing::AssertionSuccess();
}

// A source string of exactly its own length's capacity.
template <class C>
Var<C> src(const std::string& s) {
  Var<C> v(static_cast<int>(s.size()));
  const auto w = widen<C>(s);
  EXPECT_EQ(str_set(v.data(), v.cap, w.data(), w.size()), StringStatus::Ok);
  EXPECT_TRUE(invariant(v));
  return v;
}

struct Result {
  StringStatus status;
  std::string text;
};

// Runs op(dst, capacity) on a fresh destination of capacity cap and checks the invariant.
template <class C, class Op>
Result run(int cap, Op op) {
  Var<C> d(cap);
  const StringStatus st = op(d.data(), d.cap);
  EXPECT_TRUE(invariant(d));
  return {st, narrow<C>(d.data())};
}

constexpr auto Ok = StringStatus::Ok;
constexpr auto Trunc = StringStatus::Truncated;
constexpr auto Bad = StringStatus::BadArgument;

template <class C>
class StString : public ::testing::Test {};
using CharTypes = ::testing::Types<char, char16_t>;
TYPED_TEST_SUITE(StString, CharTypes);

TEST(StStringLayout, CellsLengthAndCharacters) {
  EXPECT_EQ(string_cells(0, false), 2);
  EXPECT_EQ(string_cells(7, false), 2);
  EXPECT_EQ(string_cells(8, false), 3);
  EXPECT_EQ(string_cells(80, false), 12);
  EXPECT_EQ(string_cells(255, false), 33);
  EXPECT_EQ(string_cells(0, true), 2);
  EXPECT_EQ(string_cells(3, true), 2);
  EXPECT_EQ(string_cells(4, true), 3);
  EXPECT_EQ(string_cells(80, true), 22);
  Var<char> s(10);
  ASSERT_EQ(str_set(s.data(), s.cap, "abc", 3), Ok);
  EXPECT_EQ(s.cells[0].get<std::uint64_t>(), 3u);
  EXPECT_EQ(s.cells[1].raw, 0x636261u);  // 'a' 'b' 'c' from the address of cell 1, then zeros
  EXPECT_EQ(s.cells[2].raw, 0u);
  EXPECT_STREQ(str_chars(s.data()), "abc");
  Var<char16_t> w(4);
  const std::u16string t = u"ab";
  ASSERT_EQ(str_set(w.data(), w.cap, t.data(), t.size()), Ok);
  EXPECT_EQ(w.cells[1].raw, 0x00620061u);
  // Equal strings are equal cell by cell, whatever the cells held before.
  Var<char> a(10), b(10);
  b.cells[2].raw = 0x1234;
  ASSERT_EQ(str_set(a.data(), 10, "xyzzy", 5), Ok);
  ASSERT_EQ(str_set(b.data(), 10, "xyzzy", 5), Ok);
  EXPECT_EQ(a.cells.size(), b.cells.size());
  for (std::size_t i = 0; i < a.cells.size(); ++i) EXPECT_EQ(a.cells[i].raw, b.cells[i].raw) << i;
}

TYPED_TEST(StString, AssignCutsAtTheCapacity) {
  using C = TypeParam;
  const auto abc = src<C>("abcdefgh");
  const auto empty = src<C>("");
  auto assign = [&](const Var<C>& s) { return [&s](Cell* d, int cap) { return str_assign<C>(d, cap, s.data()); }; };
  EXPECT_EQ(run<C>(20, assign(abc)).text, "abcdefgh");
  EXPECT_EQ(run<C>(8, assign(abc)).status, Ok);  // exactly full
  EXPECT_EQ(run<C>(8, assign(abc)).text, "abcdefgh");
  const Result cut = run<C>(7, assign(abc));
  EXPECT_EQ(cut.status, Trunc);
  EXPECT_EQ(cut.text, "abcdefg");
  EXPECT_EQ(run<C>(0, assign(abc)).text, "");
  EXPECT_EQ(run<C>(0, assign(abc)).status, Trunc);
  EXPECT_EQ(run<C>(0, assign(empty)).status, Ok);
  EXPECT_EQ(run<C>(5, assign(empty)).text, "");
  // A negative capacity touches nothing.
  Var<C> d(3);
  EXPECT_EQ(str_assign<C>(d.data(), -1, abc.data()), Bad);
  for (const Cell& c : d.cells) EXPECT_EQ(c.raw, 0xA5A5A5A5A5A5A5A5ULL);
}

TYPED_TEST(StString, LeftAndRight) {
  using C = TypeParam;
  const auto s = src<C>("ABCDE");
  const auto left = [&](std::int64_t l, int cap = 10) {
    return run<C>(cap, [&](Cell* d, int c) { return str_left<C>(d, c, s.data(), l); });
  };
  const auto right = [&](std::int64_t l, int cap = 10) {
    return run<C>(cap, [&](Cell* d, int c) { return str_right<C>(d, c, s.data(), l); });
  };
  const std::tuple<std::int64_t, StringStatus, std::string, std::string> cases[] = {
      {0, Ok, "", ""},           {1, Ok, "A", "E"},         {4, Ok, "ABCD", "BCDE"}, {5, Ok, "ABCDE", "ABCDE"},
      {6, Ok, "ABCDE", "ABCDE"}, {kMax, Ok, "ABCDE", "ABCDE"}, {-1, Bad, "", ""},   {kMin, Bad, "", ""}};
  for (const auto& [l, st, want_left, want_right] : cases) {
    EXPECT_EQ(left(l).status, st) << l;
    EXPECT_EQ(left(l).text, want_left) << l;
    EXPECT_EQ(right(l).status, st) << l;
    EXPECT_EQ(right(l).text, want_right) << l;
  }
  EXPECT_EQ(left(4, 3).text, "ABC");
  EXPECT_EQ(left(4, 3).status, Trunc);
  EXPECT_EQ(right(4, 3).text, "BCD");  // the result, cut at the capacity
  const auto e = src<C>("");
  EXPECT_EQ(run<C>(3, [&](Cell* d, int c) { return str_left<C>(d, c, e.data(), 1); }).text, "");
  EXPECT_EQ(run<C>(3, [&](Cell* d, int c) { return str_right<C>(d, c, e.data(), 1); }).status, Ok);
}

TYPED_TEST(StString, Mid) {
  using C = TypeParam;
  const auto s = src<C>("ABCDE");
  const std::tuple<std::int64_t, std::int64_t, StringStatus, std::string> cases[] = {
      {2, 2, Ok, "BC"},    {0, 1, Ok, ""},       {5, 1, Ok, "ABCDE"},   {9, 4, Ok, "DE"},  {1, 5, Ok, "E"},
      {1, 6, Ok, ""},      {1, 7, Bad, ""},      {1, 0, Bad, ""},       {1, -1, Bad, ""},  {-1, 2, Bad, ""},
      {kMax, 2, Ok, "BCDE"}, {1, kMax, Bad, ""}, {1, kMin, Bad, ""},    {kMin, 1, Bad, ""}};
  for (const auto& [l, p, st, want] : cases) {
    const Result r = run<C>(10, [&, l = l, p = p](Cell* d, int c) { return str_mid<C>(d, c, s.data(), l, p); });
    EXPECT_EQ(r.status, st) << "L " << l << " P " << p;
    EXPECT_EQ(r.text, want) << "L " << l << " P " << p;
  }
  const Result cut = run<C>(2, [&](Cell* d, int c) { return str_mid<C>(d, c, s.data(), 4, 2); });
  EXPECT_EQ(cut.status, Trunc);
  EXPECT_EQ(cut.text, "BC");
  // CODESYS's example: MID('SUSI', 2, 2) = 'US'.
  const auto susi = src<C>("SUSI");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_mid<C>(d, c, susi.data(), 2, 2); }).text, "US");
}

TYPED_TEST(StString, ConcatChains) {
  using C = TypeParam;
  const auto a = src<C>("abc"), b = src<C>("de"), e = src<C>("");
  auto cat = [](const Var<C>& x, const Var<C>& y) {
    return [&x, &y](Cell* d, int c) { return str_concat<C>(d, c, x.data(), y.data()); };
  };
  EXPECT_EQ(run<C>(10, cat(a, b)).text, "abcde");
  EXPECT_EQ(run<C>(5, cat(a, b)).status, Ok);
  EXPECT_EQ(run<C>(4, cat(a, b)).text, "abcd");
  EXPECT_EQ(run<C>(4, cat(a, b)).status, Trunc);
  EXPECT_EQ(run<C>(2, cat(a, b)).text, "ab");
  EXPECT_EQ(run<C>(10, cat(e, e)).text, "");
  EXPECT_EQ(run<C>(10, cat(e, b)).text, "de");
  EXPECT_EQ(run<C>(10, cat(a, e)).text, "abc");
  // CONCAT(a, b, a) as the VM chains it: through a temporary.
  Var<C> t(10), out(10);
  ASSERT_EQ(str_concat<C>(t.data(), t.cap, a.data(), b.data()), Ok);
  ASSERT_EQ(str_concat<C>(out.data(), out.cap, t.data(), a.data()), Ok);
  EXPECT_EQ(narrow<C>(out.data()), "abcdeabc");
  EXPECT_TRUE(invariant(out));
}

TYPED_TEST(StString, Insert) {
  using C = TypeParam;
  const auto s = src<C>("ABCDE"), x = src<C>("xy"), e = src<C>("");
  const std::tuple<std::int64_t, StringStatus, std::string> cases[] = {
      {0, Ok, "xyABCDE"},  {1, Ok, "AxyBCDE"},   {2, Ok, "ABxyCDE"},    {4, Ok, "ABCDxyE"},
      {5, Ok, "ABCDExy"},  {6, Bad, "ABCDExy"},  {-1, Bad, "xyABCDE"},  {kMax, Bad, "ABCDExy"},
      {kMin, Bad, "xyABCDE"}};
  for (const auto& [p, st, want] : cases) {
    const Result r = run<C>(10, [&, p = p](Cell* d, int c) { return str_insert<C>(d, c, s.data(), x.data(), p); });
    EXPECT_EQ(r.status, st) << p;
    EXPECT_EQ(r.text, want) << p;
  }
  const Result cut = run<C>(5, [&](Cell* d, int c) { return str_insert<C>(d, c, s.data(), x.data(), 2); });
  EXPECT_EQ(cut.status, Trunc);
  EXPECT_EQ(cut.text, "ABxyC");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_insert<C>(d, c, e.data(), x.data(), 0); }).text, "xy");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_insert<C>(d, c, s.data(), e.data(), 3); }).text, "ABCDE");
  // CODESYS's example: INSERT('SUSI', 'XY', 2) = 'SUXYSI'.
  const auto susi = src<C>("SUSI"), xy = src<C>("XY");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_insert<C>(d, c, susi.data(), xy.data(), 2); }).text,
            "SUXYSI");
}

TYPED_TEST(StString, Delete) {
  using C = TypeParam;
  const auto s = src<C>("ABCDE");
  const std::tuple<std::int64_t, std::int64_t, StringStatus, std::string> cases[] = {
      {2, 2, Ok, "ADE"},      {0, 3, Ok, "ABCDE"},     {9, 4, Ok, "ABC"},      {1, 5, Ok, "ABCD"},
      {1, 1, Ok, "BCDE"},     {5, 1, Ok, ""},          {1, 6, Ok, "ABCDE"},    {1, 7, Bad, "ABCDE"},
      {1, 0, Bad, "ABCDE"},   {1, -3, Bad, "ABCDE"},   {-1, 2, Bad, "ABCDE"},  {kMax, 1, Ok, ""},
      {kMax, 3, Ok, "AB"},    {1, kMax, Bad, "ABCDE"}, {1, kMin, Bad, "ABCDE"}, {kMin, 2, Bad, "ABCDE"}};
  for (const auto& [l, p, st, want] : cases) {
    const Result r = run<C>(10, [&, l = l, p = p](Cell* d, int c) { return str_delete<C>(d, c, s.data(), l, p); });
    EXPECT_EQ(r.status, st) << "L " << l << " P " << p;
    EXPECT_EQ(r.text, want) << "L " << l << " P " << p;
  }
  EXPECT_EQ(run<C>(3, [&](Cell* d, int c) { return str_delete<C>(d, c, s.data(), 1, 1); }).status, Trunc);
  // CODESYS's example: DELETE('SUXYSI', 2, 3) = 'SUSI'.
  const auto sux = src<C>("SUXYSI");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_delete<C>(d, c, sux.data(), 2, 3); }).text, "SUSI");
  const auto e = src<C>("");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_delete<C>(d, c, e.data(), 1, 1); }).status, Ok);
}

TYPED_TEST(StString, Replace) {
  using C = TypeParam;
  const auto s = src<C>("ABCDE"), x = src<C>("xy");
  const std::tuple<std::int64_t, std::int64_t, StringStatus, std::string> cases[] = {
      {2, 2, Ok, "AxyDE"},        {0, 3, Ok, "ABxyCDE"},     {9, 4, Ok, "ABCxy"},      {1, 1, Ok, "xyBCDE"},
      {1, 5, Ok, "ABCDxy"},       {1, 6, Ok, "ABCDExy"},     {1, 7, Bad, "ABCDExy"},   {1, 0, Bad, "xyABCDE"},
      {-1, 2, Bad, "AxyBCDE"},    {kMax, 2, Ok, "Axy"},      {3, kMax, Bad, "ABCDExy"}, {3, kMin, Bad, "xyABCDE"},
      {kMin, 1, Bad, "xyABCDE"}};
  for (const auto& [l, p, st, want] : cases) {
    const Result r = run<C>(10, [&, l = l, p = p](Cell* d, int c) { return str_replace<C>(d, c, s.data(), x.data(), l, p); });
    EXPECT_EQ(r.status, st) << "L " << l << " P " << p;
    EXPECT_EQ(r.text, want) << "L " << l << " P " << p;
  }
  const Result cut = run<C>(4, [&](Cell* d, int c) { return str_replace<C>(d, c, s.data(), x.data(), 1, 3); });
  EXPECT_EQ(cut.status, Trunc);
  EXPECT_EQ(cut.text, "ABxy");
  // CODESYS's example: REPLACE('SUXYSI', 'K', 2, 2) = 'SKYSI'.
  const auto sux = src<C>("SUXYSI"), k = src<C>("K");
  EXPECT_EQ(run<C>(10, [&](Cell* d, int c) { return str_replace<C>(d, c, sux.data(), k.data(), 2, 2); }).text,
            "SKYSI");
}

TYPED_TEST(StString, Find) {
  using C = TypeParam;
  const auto f = [](const std::string& a, const std::string& b) {
    const auto x = src<C>(a), y = src<C>(b);
    return str_find<C>(x.data(), y.data());
  };
  EXPECT_EQ(f("abcabc", "ca"), 3);
  EXPECT_EQ(f("abcabc", "abc"), 1);
  EXPECT_EQ(f("abcabc", "c"), 3);
  EXPECT_EQ(f("abc", "abc"), 1);
  EXPECT_EQ(f("abc", "abcd"), 0);
  EXPECT_EQ(f("abc", "x"), 0);
  EXPECT_EQ(f("abc", ""), 0);
  EXPECT_EQ(f("", ""), 0);
  EXPECT_EQ(f("", "a"), 0);
  EXPECT_EQ(f("aab", "ab"), 2);
}

TYPED_TEST(StString, CompareOrdersCharacterByCharacter) {
  using C = TypeParam;
  const auto cmp = [](const std::string& a, const std::string& b) {
    const auto x = src<C>(a), y = src<C>(b);
    const int r = str_compare<C>(x.data(), y.data());
    return r < 0 ? -1 : r > 0 ? 1 : 0;
  };
  EXPECT_EQ(cmp("abc", "abc"), 0);
  EXPECT_EQ(cmp("", ""), 0);
  EXPECT_EQ(cmp("abc", "abd"), -1);
  EXPECT_EQ(cmp("abd", "abc"), 1);
  EXPECT_EQ(cmp("ab", "abc"), -1);  // a proper prefix is before
  EXPECT_EQ(cmp("abc", "ab"), 1);
  EXPECT_EQ(cmp("", "a"), -1);
  EXPECT_EQ(cmp("B", "a"), -1);  // by code, not by letter
  EXPECT_EQ(cmp("\xff", "a"), 1);  // unsigned: 0xFF after 'a'
  // Equal strings in variables of different capacities are equal.
  Var<C> a(3), b(30);
  const auto t = widen<C>("xy");
  ASSERT_EQ(str_set(a.data(), a.cap, t.data(), t.size()), Ok);
  ASSERT_EQ(str_set(b.data(), b.cap, t.data(), t.size()), Ok);
  EXPECT_EQ(str_compare<C>(a.data(), b.data()), 0);
}

TEST(StStringWide, Utf8LiteralsAsUtf16) {
  Var<char16_t> w(10);
  const std::string s = "a\xc3\xa4\xe2\x82\xac\xf0\x9f\x98\x80";  // a ä € 😀
  EXPECT_EQ(wstr_set_utf8(w.data(), w.cap, s.data(), s.size()), Ok);
  EXPECT_EQ(text_of<char16_t>(w.data()), u"a\u00e4\u20ac\U0001F600");
  EXPECT_EQ(str_len(w.data()), 5);  // the emoji takes a surrogate pair
  EXPECT_TRUE(invariant(w));
  // A pair that does not fit whole is left out, not split.
  Var<char16_t> small(4);
  EXPECT_EQ(wstr_set_utf8(small.data(), small.cap, s.data(), s.size()), Trunc);
  EXPECT_EQ(text_of<char16_t>(small.data()), u"a\u00e4\u20ac");
  EXPECT_TRUE(invariant(small));
  // Malformed: a lone continuation byte, a cut sequence, an overlong form, a surrogate.
  for (const std::string bad : {"x\x80y", "x\xe2\x82", "\xc0\xaf", "\xed\xa0\x80"}) {
    Var<char16_t> b(10);
    EXPECT_EQ(wstr_set_utf8(b.data(), b.cap, bad.data(), bad.size()), Bad) << bad;
    EXPECT_NE(text_of<char16_t>(b.data()).find(u'\uFFFD'), std::u16string::npos) << bad;
    EXPECT_TRUE(invariant(b));
  }
  // Units above 0x7F compare unsigned.
  Var<char16_t> hi(2), lo(2);
  const std::u16string h = u"\uFFFF", l = u"z";
  ASSERT_EQ(str_set(hi.data(), 2, h.data(), 1), Ok);
  ASSERT_EQ(str_set(lo.data(), 2, l.data(), 1), Ok);
  EXPECT_GT(str_compare<char16_t>(hi.data(), lo.data()), 0);
}

// ---- conversions ----------------------------------------------------------------

template <class T>
Cell cell_of(T v) {
  Cell c;
  c.set<T>(v);
  return c;
}

std::string to_text(IecType t, Cell v, int cap = 64, StringStatus* st = nullptr) {
  Var<char> d(cap);
  const StringStatus s = to_string<char>(t, v, d.data(), d.cap);
  EXPECT_TRUE(invariant(d));
  if (st) *st = s;
  return narrow<char>(d.data());
}

TEST(StStringConvert, ValuesAsText) {
  EXPECT_EQ(to_text(IecType::BOOL, cell_of(true)), "TRUE");
  EXPECT_EQ(to_text(IecType::BOOL, cell_of(false)), "FALSE");
  EXPECT_EQ(to_text(IecType::INT, cell_of<std::int16_t>(-32768)), "-32768");
  EXPECT_EQ(to_text(IecType::LINT, cell_of(kMin)), "-9223372036854775808");
  EXPECT_EQ(to_text(IecType::ULINT, cell_of(std::numeric_limits<std::uint64_t>::max())), "18446744073709551615");
  EXPECT_EQ(to_text(IecType::BYTE, cell_of<std::uint8_t>(0xFF)), "255");  // decimal, as CODESYS
  EXPECT_EQ(to_text(IecType::WORD, cell_of<std::uint16_t>(0x1234)), "4660");
  EXPECT_EQ(to_text(IecType::REAL, cell_of(1.5f)), "1.5");
  EXPECT_EQ(to_text(IecType::REAL, cell_of(0.1f)), "0.1");  // the float's shortest text, not 0.100000001
  EXPECT_EQ(to_text(IecType::LREAL, cell_of(0.35)), "0.35");
  EXPECT_EQ(to_text(IecType::LREAL, cell_of(-1e300)), "-1e+300");
  EXPECT_EQ(to_text(IecType::TIME, cell_of<std::int64_t>(1'500'000'000)), "T#1s500ms");
  EXPECT_EQ(to_text(IecType::TIME, cell_of<std::int64_t>(0)), "T#0ms");
  EXPECT_EQ(to_text(IecType::TIME, cell_of<std::int64_t>(-90'000'000'001)), "T#-1m30s1ns");
  EXPECT_EQ(to_text(IecType::TIME, cell_of(kMin)), "T#-2562047h47m16s854ms775us808ns");
  StringStatus st;
  EXPECT_EQ(to_text(IecType::INT, cell_of<std::int16_t>(-32768), 3, &st), "-32");
  EXPECT_EQ(st, Trunc);
  Var<char16_t> w(20);
  EXPECT_EQ(to_string<char16_t>(IecType::TIME, cell_of<std::int64_t>(2'000'000), w.data(), w.cap), Ok);
  EXPECT_EQ(text_of<char16_t>(w.data()), u"T#2ms");
  EXPECT_TRUE(invariant(w));
}

// Values of every type that reach each limit and each text form.
std::vector<Cell> samples(IecType t) {
  std::vector<Cell> out;
  std::mt19937_64 rng(42);
  dispatch_type(t, [&]<IecType T>() {
    using N = typename Native<T>::type;
    using L = std::numeric_limits<N>;
    if constexpr (T == IecType::BOOL) {
      out = {cell_of(false), cell_of(true)};
    } else if constexpr (std::is_floating_point_v<N>) {
      for (N v : {N(0), N(-0.0), N(1.5), N(-2.25), N(0.1), N(1) / N(3), L::max(), L::lowest(), L::min(),
                  L::denorm_min(), N(1e10), N(123456789)})
        out.push_back(cell_of(v));
      for (int i = 0; i < 200; ++i) {
        N v;
        do {
          std::uint64_t bits = rng();
          std::memcpy(&v, &bits, sizeof v);
        } while (!std::isfinite(v));
        out.push_back(cell_of(v));
      }
    } else {
      for (N v : {L::min(), L::max(), N(0), N(1), static_cast<N>(L::max() / 2)}) out.push_back(cell_of(v));
      if constexpr (T == IecType::TIME) out.push_back(cell_of<N>(-1));
      for (int i = 0; i < 200; ++i) out.push_back(cell_of(static_cast<N>(rng())));
    }
  });
  return out;
}

TEST(StStringConvert, TextsAgreeWithFormatValueAndReadBack) {
  for (int i = 0; i < kIecTypeCount; ++i) {
    const auto t = static_cast<IecType>(i);
    for (const Cell v : samples(t)) {
      const std::string text = to_text(t, v);
      if (!is_bit_string(t) || t == IecType::BOOL) {
        EXPECT_EQ(text, format_value(t, v)) << type_name(t);  // the same text as the rest of syncplc
      }
      // parse_value reads it back to the same value, and so does from_string.
      std::string err;
      const auto back = parse_value(t, text, &err);
      ASSERT_TRUE(back) << type_name(t) << " " << text << ": " << err;
      EXPECT_EQ(back->raw, v.raw) << type_name(t) << " " << text;
      const auto s = src<char>(text);
      Cell mine;
      EXPECT_EQ(from_string<char>(t, s.data(), &mine), Ok) << type_name(t) << " " << text;
      EXPECT_EQ(mine.raw, v.raw) << type_name(t) << " " << text;
      // The same through a WSTRING.
      const auto w = src<char16_t>(text);
      Cell wide;
      EXPECT_EQ(from_string<char16_t>(t, w.data(), &wide), Ok) << type_name(t) << " " << text;
      EXPECT_EQ(wide.raw, v.raw) << type_name(t) << " " << text;
    }
  }
}

// Every text in every type: where parse_value reads a value, from_string
// reads the same; where parse_value refuses, from_string says BadArgument.
TEST(StStringConvert, ReadsWhatParseValueReads) {
  const char* texts[] = {
      "0", "1", "-1", "+7", " 42 ", "1_000", "16#FF", "16#ff", "-16#80", "8#17", "2#1010", "0x1F", "0b101",
      "16#", "0x", "12a", "--1", "", "   ", "TRUE", "false", "On", "no", "yes", "BOOL#TRUE", "INT#5", "int#-5",
      "REAL#1.5", "LREAL#2.5", "WORD#16#FFFF", "DINT#5", "LTIME#1s", "FOO#5", "1.5", "-0.25", "1e3", "1.5e-3",
      "+2.5", ".5", "5.", "1e39", "-1e39", "1e309", "1e-400", "nan", "inf", "-inf", "1.7976931348623157e308",
      "3.4028235e38", "3.4028236e38", "255", "256", "-129", "127", "128", "65535", "65536", "4294967295",
      "4294967296", "9223372036854775807", "9223372036854775808", "-9223372036854775808", "-9223372036854775809",
      "18446744073709551615", "18446744073709551616", "99999999999999999999999", "T#1s", "t#1s500ms", "1ms",
      "250us", "0.5s", "2m", "1h30m", "100ns", "1d", "TIME#250ms", "LT#3ms", "T#-5s", "-5s", "T#1m1h", "T#1",
      "T#", "1 ms", "T#1.5.5s", "T#106752d", "T#-106751d23h47m16s854ms775us808ns", "T#106751d23h47m16s854ms775us807ns",
      "T#1min", "T#1_000ms", "1.5.5", "0.0", "-0", "-0.0", "TRUE#1", "  INT#  5", "1e", "0x-1"};
  for (int i = 0; i < kIecTypeCount; ++i) {
    const auto t = static_cast<IecType>(i);
    for (const char* text : texts) {
      std::string err;
      const auto want = parse_value(t, text, &err);
      for (bool wide : {false, true}) {
        Cell got;
        got.raw = 0x5A5A;
        StringStatus st;
        if (wide) {
          const auto s = src<char16_t>(text);
          st = from_string<char16_t>(t, s.data(), &got);
        } else {
          const auto s = src<char>(text);
          st = from_string<char>(t, s.data(), &got);
        }
        if (want) {
          EXPECT_EQ(st, Ok) << type_name(t) << " '" << text << "'";
          EXPECT_EQ(got.raw, want->raw) << type_name(t) << " '" << text << "'";
        } else {
          EXPECT_EQ(st, Bad) << type_name(t) << " '" << text << "' (" << err << ")";
        }
      }
    }
  }
}

Cell parse(IecType t, const std::string& text, StringStatus* st) {
  const auto s = src<char>(text);
  Cell c;
  *st = from_string<char>(t, s.data(), &c);
  return c;
}

TEST(StStringConvert, InvalidGivesZeroOutOfRangeSaturates) {
  StringStatus st;
  EXPECT_EQ(parse(IecType::INT, "12a", &st).raw, 0u);
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::LREAL, "nan", &st).raw, 0u);
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::BOOL, "maybe", &st).raw, 0u);
  EXPECT_EQ(parse(IecType::TIME, "T#1x", &st).raw, 0u);
  EXPECT_EQ(parse(IecType::INT, "REAL#1", &st).raw, 0u);  // a prefix of another type
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::SINT, "200", &st).get<std::int8_t>(), 127);
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::SINT, "-200", &st).get<std::int8_t>(), -128);
  EXPECT_EQ(parse(IecType::UINT, "-1", &st).get<std::uint16_t>(), 0);
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::BYTE, "16#100", &st).get<std::uint8_t>(), 255);
  EXPECT_EQ(parse(IecType::ULINT, "99999999999999999999999999999999999999999", &st).get<std::uint64_t>(),
            std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::LINT, "-99999999999999999999999999999999999999999", &st).get<std::int64_t>(), kMin);
  EXPECT_EQ(parse(IecType::REAL, "1e39", &st).get<float>(), std::numeric_limits<float>::max());
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::REAL, "-1e300", &st).get<float>(), -std::numeric_limits<float>::max());
  EXPECT_EQ(parse(IecType::LREAL, "1e999", &st).get<double>(), std::numeric_limits<double>::max());
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::LREAL, "-1" + std::string(200, '0') + "e200", &st).get<double>(),
            -std::numeric_limits<double>::max());
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::LREAL, "1e-999", &st).get<double>(), 0.0);  // underflow: zero
  EXPECT_EQ(st, Bad);
  // Past a long double's range too: the exponent's sign tells.
  EXPECT_EQ(parse(IecType::LREAL, "1e99999", &st).get<double>(), std::numeric_limits<double>::max());
  EXPECT_EQ(parse(IecType::LREAL, "1e-99999", &st).get<double>(), 0.0);
  EXPECT_EQ(parse(IecType::LREAL, "0.0001e99999", &st).get<double>(), std::numeric_limits<double>::max());
  EXPECT_EQ(parse(IecType::TIME, "T#200000d", &st).get<std::int64_t>(), kMax);
  EXPECT_EQ(st, Bad);
  EXPECT_EQ(parse(IecType::TIME, "T#-200000d", &st).get<std::int64_t>(), kMin);
  EXPECT_EQ(st, Bad);
  // Spaces around are trimmed before the length limit counts.
  EXPECT_EQ(parse(IecType::INT, std::string(300, ' ') + "12" + std::string(300, '\t'), &st).get<std::int16_t>(), 12);
  EXPECT_EQ(st, Ok);
  EXPECT_EQ(parse(IecType::INT, std::string(300, '0') + "12", &st).raw, 0u);
  EXPECT_EQ(st, Bad);  // longer than kMaxNumberText: not read
  EXPECT_EQ(parse(IecType::INT, std::string("1\0" "2", 3), &st).raw, 0u);
  EXPECT_EQ(st, Bad);
  // A WSTRING character beyond ASCII is in no number.
  Var<char16_t> w(4);
  const std::u16string t = u"1\u0661";
  ASSERT_EQ(str_set(w.data(), w.cap, t.data(), t.size()), Ok);
  Cell c;
  EXPECT_EQ(from_string<char16_t>(IecType::INT, w.data(), &c), Bad);
  EXPECT_EQ(c.raw, 0u);
}

}  // namespace st_string_test
}  // namespace syncplc::st::vm
