// Random programs on both engines (runtime/st/vm/native_x64.cpp against the
// interpreter): every numeric type's arithmetic, comparisons, clamps and
// widenings at its limits and with NaN, arrays with negative, 32-bit-wide and
// far bounds indexed by every integer type, nested FOR/WHILE/REPEAT left by
// EXIT, CONTINUE and RETURN, CASE by table and label by label, bits of bit
// strings, FB calls (through VAR_IN_OUT too) and FUNCTIONs with loops of
// their own, loops with more cells than registers, and budgets that stop
// the scan anywhere. After every scan the frames, the faults and the stop
// must agree as in test_vm_native.cpp. NATIVE_RANDOM_N and NATIVE_RANDOM_SEED
// run a longer campaign (14 seeds x 400 programs passed on 2026-11-29).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "runtime/st/vm/same_cell.hpp"
#include "tests/st/vm_fixture.hpp"

namespace syncplc::st::testing {
namespace {

using vm::same_cell;

struct TypeInfo {
  const char* name;
  char kind;  // 'i' signed, 'u' unsigned, 'f' real, 'b' bool
  int bits;
};
const TypeInfo kTypes[] = {{"SINT", 'i', 8},  {"INT", 'i', 16},  {"DINT", 'i', 32},  {"LINT", 'i', 64},
                           {"USINT", 'u', 8}, {"UINT", 'u', 16}, {"UDINT", 'u', 32}, {"ULINT", 'u', 64},
                           {"REAL", 'f', 32}, {"LREAL", 'f', 64}};
constexpr int kNT = 10;

struct Gen {
  std::mt19937_64 rng;
  std::string out;
  int depth = 0;
  int loops = 0;  // enclosing loops
  std::vector<std::string> busy;  // control variables in use
  explicit Gen(std::uint64_t seed) : rng(seed) {}
  int r(int n) { return static_cast<int>(rng() % static_cast<std::uint64_t>(n)); }
  bool p(int percent) { return r(100) < percent; }

  std::string var(int t) { return std::string("v") + std::to_string(t) + "_" + std::to_string(r(3)); }
  std::string arr(int t) { return std::string("a") + std::to_string(t); }
  static std::int64_t low_of(int t) { return t % 3 == 0 ? -3 : t % 3 == 1 ? 2 : 0; }
  std::string index_expr() {
    // an integer expression of any integer type, often near the bounds
    const int t = r(8);
    switch (r(4)) {
      case 0: return var(t);
      case 1: return "k" + std::to_string(r(3));
      case 2: return "(k" + std::to_string(r(3)) + " + " + std::to_string(r(3)) + ")";
      default: return "c" + std::to_string(t);
    }
  }
  std::string lit(int t) {
    if (kTypes[t].kind == 'f') {
      const char* v[] = {"0.0", "1.5", "-2.25", "0.5", "1.0E30", "3.0"};
      return v[r(6)];
    }
    if (kTypes[t].kind == 'u') return std::to_string(r(5));
    const int v = r(7) - 3;
    return v < 0 ? "(" + std::to_string(v) + ")" : std::to_string(v);
  }
  std::string expr(int t, int d) {
    const int c = r(d > 2 ? 3 : 12);
    switch (c) {
      case 8: case 9: return var(t);
      case 10: case 11: return "(" + expr(t, d + 1) + " + " + expr(t, d + 1) + ")";
      case 0: return var(t);
      case 1: return lit(t);
      case 2: return arr(t) + "[" + index_expr() + "]";
      case 3: case 4: {
        const char* ops[] = {" + ", " - ", " * "};
        return "(" + expr(t, d + 1) + ops[r(3)] + expr(t, d + 1) + ")";
      }
      case 5:
        if (kTypes[t].kind == 'f') return "(" + expr(t, d + 1) + " * " + expr(t, d + 1) + " + " + expr(t, d + 1) + ")";
        return "(" + expr(t, d + 1) + " MOD " + var(t) + ")";
      case 6:
        if (t == 9) return var(r(8) == 3 || r(2) ? 2 + r(2) * 6 : 8);  // widen DINT/UDINT/REAL... to LREAL
        if (t == 3) return var(r(3));  // SINT/INT/DINT to LINT
        return var(t);
      case 7: return "(" + expr(t, d + 1) + " / " + var(t) + ")";
      default: return var(t);
    }
  }
  std::string cond(int d) {
    switch (r(d > 1 ? 3 : 7)) {
      case 6: { const int w = r(4); return "w" + std::to_string(w) + "." + std::to_string(r(8 << w)); }
      case 0: return "b" + std::to_string(r(3));
      case 1: case 2: {
        const int t = r(kNT);
        const char* ops[] = {" < ", " <= ", " > ", " >= ", " = ", " <> "};
        return "(" + expr(t, 2) + ops[r(6)] + expr(t, 2) + ")";
      }
      case 3: return "(" + cond(d + 1) + (r(2) ? " AND " : " OR ") + cond(d + 1) + ")";
      case 4: return "NOT " + cond(d + 1);
      default: return "(" + cond(d + 1) + " XOR " + cond(d + 1) + ")";
    }
  }
  void line(const std::string& s) { out += std::string(static_cast<std::size_t>(depth) * 2, ' ') + s + "\n"; }
  void stmts(int n) {
    for (int k = 0; k < n; ++k) stmt();
  }
  void stmt() {
    const int c = r(depth > 3 ? 4 : 26);
    switch (c) {
      case 20: {  // WHILE TRUE: its body's first instruction is its head
        line("WHILE TRUE DO");
        ++depth; ++loops; stmts(1 + r(3)); line("IF " + cond(0) + " THEN EXIT; END_IF;"); --loops; --depth;
        line("END_WHILE;");
        return;
      }
      case 21: {  // two loops with one head
        line("REPEAT");
        ++depth; ++loops;
        line("REPEAT");
        ++depth; ++loops; stmts(1 + r(2)); --loops; --depth;
        line("UNTIL " + cond(0) + " END_REPEAT;");
        stmts(r(2));
        --loops; --depth;
        line("UNTIL " + cond(0) + " END_REPEAT;");
        return;
      }
      case 22: {  // a body that starts by jumping to its end
        line("REPEAT");
        ++depth; ++loops;
        line(r(2) ? "CONTINUE;" : "IF " + cond(0) + " THEN CONTINUE; END_IF;");
        stmts(1 + r(2));
        --loops; --depth;
        line("UNTIL " + cond(0) + " END_REPEAT;");
        return;
      }
      case 23: {  // FOR with a step in a variable
        std::string k = "k" + std::to_string(r(3));
        for (auto& b : busy) if (b == k) return;
        line("FOR " + k + " := " + var(1) + " TO " + var(1) + " BY " + var(1) + " DO");
        ++depth; ++loops; busy.push_back(k); stmts(1 + r(3)); busy.pop_back(); --loops; --depth;
        line("END_FOR;");
        return;
      }
      case 24: line("fr(inner := fb" + std::to_string(r(2)) + ", io := " + var(9) + ", n := " + var(2) + ");"); return;
      case 25: line(var(2) + " := G(" + var(2) + ", " + var(9) + ");"); return;
      case 14: line("fb" + std::to_string(r(2)) + "(n := " + var(2) + ", io := " + var(9) + ");"); return;
      case 15: line(var(9) + " := F(" + expr(9, 1) + ", k" + std::to_string(r(3)) + ");"); return;
      case 16: {
        const int w = r(4);
        line("w" + std::to_string(w) + "." + std::to_string(r(8 << w)) + " := " + cond(1) + ";");
        return;
      }
      case 17: line("big[" + (r(2) ? var(2) : "(" + var(2) + " * 1000)") + "] := " + expr(9, 1) + ";");
               line(var(9) + " := big[" + var(2) + "] + big[" + (r(2) ? var(2) : "(" + var(2) + " - 70000)") + "];"); return;
      case 18: {
        const char* ix[] = {"v3_0", "v6_1", "v7_2", "kk3", "(kk3 + 3000000000)", "(v6_0 + 1)"};
        line("far[" + std::string(ix[r(6)]) + "] := far[" + ix[r(6)] + "] + " + var(2) + ";");
        return;
      }
      case 19: {  // a loop with many LREALs and integers alive
        std::string k = "k" + std::to_string(r(3));
        for (auto& b : busy) if (b == k) return;
        line("FOR " + k + " := 0 TO " + var(1) + " DO");
        ++depth; ++loops; busy.push_back(k);
        for (int q = 0; q < 8; ++q) line(var(9) + " := " + var(9) + " * " + var(9) + " + m" + std::to_string(r(14)) + ";");
        for (int q = 0; q < 5; ++q) line("n" + std::to_string(r(8)) + " := n" + std::to_string(r(8)) + " + " + var(2 + r(2)) + ";");
        for (int q = 0; q < 3; ++q) line("m" + std::to_string(r(14)) + " := m" + std::to_string(r(14)) + " - " + var(9) + ";");
        if (p(50)) stmt();
        busy.pop_back(); --loops; --depth;
        line("END_FOR;");
        return;
      }
      case 0: case 1: {
        const int t = r(kNT);
        line(var(t) + " := " + expr(t, 0) + ";");
        return;
      }
      case 2: {
        const int t = r(kNT);
        line(arr(t) + "[" + index_expr() + "] := " + expr(t, 0) + ";");
        return;
      }
      case 3: {
        if (loops > 0 && p(40)) {
          line("IF " + cond(0) + " THEN " + (r(3) == 0 ? "RETURN" : r(2) ? "EXIT" : "CONTINUE") + "; END_IF;");
          return;
        }
        line("b" + std::to_string(r(3)) + " := " + cond(0) + ";");
        return;
      }
      case 4: case 5: {
        line("IF " + cond(0) + " THEN");
        ++depth; stmts(1 + r(3)); --depth;
        if (p(40)) { line("ELSIF " + cond(0) + " THEN"); ++depth; stmts(1 + r(2)); --depth; }
        if (p(40)) { line("ELSE"); ++depth; stmts(1 + r(2)); --depth; }
        line("END_IF;");
        return;
      }
      case 6: {  // the clamp
        const int t = r(kNT);
        const std::string x = var(t), lo = p(50) ? var(t) : lit(t), hi = p(50) ? var(t) : lit(t);
        if (p(50)) line("IF " + x + " > " + hi + " THEN " + x + " := " + hi + "; ELSIF " + x + " < " + lo + " THEN " + x + " := " + lo + "; END_IF;");
        else line("IF " + x + " < " + lo + " THEN " + x + " := " + lo + "; ELSIF " + x + " > " + hi + " THEN " + x + " := " + hi + "; END_IF;");
        return;
      }
      case 7: case 8: case 9: {  // FOR
        std::string k;
        for (int tries = 0; tries < 5; ++tries) {
          const std::string cand = r(3) ? "k" + std::to_string(r(3)) : "kk" + std::to_string(r(8));
          bool used = false;
          for (auto& b : busy) used = used || b == cand;
          if (!used) { k = cand; break; }
        }
        if (k.empty()) return;
        const int kt = k[1] == 'k' ? k[2] - '0' : 1;  // kk<t> is of type t; k<n> is INT
        std::string from = p(50) ? lit(kt) : var(kt), to = p(50) ? lit(kt) : var(kt);
        if (p(20)) to = "c" + std::to_string(kt);
        if (kTypes[kt].kind == 'u' && p(20)) to = "(" + from + " + 7)";
        std::string by;
        if (p(25)) by = kTypes[kt].kind == 'u' ? " BY 2" : (p(50) ? " BY -1" : " BY 3");
        line("FOR " + k + " := " + from + " TO " + to + by + " DO");
        busy.push_back(k);
        ++depth; ++loops; stmts(1 + r(4)); --loops; --depth;
        busy.pop_back();
        line("END_FOR;");
        return;
      }
      case 10: {
        line("WHILE " + cond(0) + " DO");
        ++depth; ++loops; stmts(1 + r(3)); --loops; --depth;
        line("END_WHILE;");
        return;
      }
      case 11: {
        line("REPEAT");
        ++depth; ++loops; stmts(1 + r(3)); --loops; --depth;
        line("UNTIL " + cond(0) + " END_REPEAT;");
        return;
      }
      case 12: {
        const int t = r(8);
        line("CASE " + var(t) + " OF");
        ++depth;
        const int base = kTypes[t].kind == 'u' ? 0 : -2;
        if (p(50)) {
          line(std::to_string(base + 1) + ": "); ++depth; stmts(1 + r(2)); --depth;
          line(std::to_string(base + 2) + ".." + std::to_string(base + 4) + ": "); ++depth; stmts(1 + r(2)); --depth;
        } else {
          line(std::to_string(base + 1) + ", 100: "); ++depth; stmts(1 + r(2)); --depth;
        }
        --depth;
        line("ELSE");
        ++depth; stmts(1); --depth;
        line("END_CASE;");
        return;
      }
      default: {
        const int t = r(8);
        line(var(t) + " := " + var(t) + " + " + lit(t) + ";");
        return;
      }
    }
  }
  std::string program() {
    std::string src = "PROGRAM P\nVAR\n";
    for (int t = 0; t < kNT; ++t) {
      src += "  v" + std::to_string(t) + "_0, v" + std::to_string(t) + "_1, v" + std::to_string(t) + "_2, kk" +
             std::to_string(t) + " : " + kTypes[t].name + ";\n";
      const std::int64_t lo = low_of(t);
      src += "  a" + std::to_string(t) + " : ARRAY[" + std::to_string(lo) + ".." + std::to_string(lo + 7) + "] OF " +
             kTypes[t].name + ";\n";
      src += "  c" + std::to_string(t) + " : " + kTypes[t].name + ";\n";
    }
    src += "  k0, k1, k2 : INT;\n  b0, b1, b2 : BOOL;\n  fr : FBREF;\n  fb0, fb1 : FB;\n  w0 : BYTE; w1 : WORD; w2 : DWORD; w3 : LWORD;\n  big : ARRAY[-70000..70000] OF LREAL;\n"
           "  far : ARRAY[3000000000..3000000007] OF LINT;\n"
           "  m0, m1, m2, m3, m4, m5, m6, m7, m8, m9, m10, m11, m12, m13 : LREAL;\n"
           "  n0, n1, n2, n3, n4, n5, n6, n7 : LINT;\nEND_VAR\n";
    src = R"(
FUNCTION F : LREAL
VAR_INPUT x : LREAL; n : INT; END_VAR
VAR i : INT; acc : LREAL; END_VAR
acc := x;
F := -1.0;
FOR i := 1 TO n DO
  acc := acc * 0.5 + x;
  IF acc > 100.0 THEN RETURN; END_IF;
END_FOR;
F := acc;
END_FUNCTION
FUNCTION_BLOCK FB
VAR_INPUT n : DINT; END_VAR
VAR_IN_OUT io : LREAL; END_VAR
VAR_OUTPUT q : DINT; END_VAR
VAR j : DINT; t : ARRAY[-2..5] OF LREAL; s : LREAL; END_VAR
FOR j := -2 TO n DO
  t[j] := t[j] * 0.5 + s;
  s := s + t[j];
  q := q + j;
END_FOR;
io := io + s;
WHILE q > 1000 DO q := q - 999; END_WHILE;
END_FUNCTION_BLOCK
FUNCTION_BLOCK FBREF
VAR_INPUT n : DINT; END_VAR
VAR_IN_OUT inner : FB; io : LREAL; END_VAR
VAR_TEMP i : DINT; acc : LREAL; END_VAR
VAR tot : LREAL; END_VAR
acc := io;
FOR i := 0 TO n DO
  acc := acc * 0.25 + tot;
  IF i > 5 THEN EXIT; END_IF;
END_FOR;
inner(n := n, io := io);
WHILE i > 0 DO
  i := i - 1;
  tot := tot + acc;
END_WHILE;
io := acc;
END_FUNCTION_BLOCK
FUNCTION G : DINT
VAR_INPUT n : DINT; x : LREAL; END_VAR
VAR i : DINT; a : ARRAY[-4..4] OF DINT; END_VAR
G := 0;
FOR i := -4 TO 4 DO a[i] := i * n; END_FOR;
FOR i := n TO 4 DO
  G := G + a[i];
  IF x > 1.0 THEN RETURN; END_IF;
END_FOR;
END_FUNCTION
)" + src;
    out.clear();
    stmts(3 + r(6));
    return src + out + "END_PROGRAM\n";
  }
};

template <class C>
C pick(std::mt19937_64& rng) {
  using L = std::numeric_limits<C>;
  std::vector<C> v = {C(0), C(1), C(2), C(3), C(7), L::max(), L::lowest(), C(L::max() - C(1))};
  if constexpr (std::is_signed_v<C>) v.push_back(C(-1)), v.push_back(C(-3)), v.push_back(C(-4));
  if constexpr (std::is_floating_point_v<C>) {
    v.push_back(L::quiet_NaN());
    v.push_back(L::infinity());
    v.push_back(C(-0.0));
    v.push_back(C(0.5));
  }
  return v[rng() % v.size()];
}

void set_random(StRun& a, StRun& b, std::mt19937_64& rng, const std::string& name, int t) {
  auto both = [&](auto v) {
    a.set(name, v);
    b.set(name, v);
  };
  switch (t) {
    case 0: both(pick<std::int8_t>(rng)); break;
    case 1: both(pick<std::int16_t>(rng)); break;
    case 2: both(pick<std::int32_t>(rng)); break;
    case 3: both(pick<std::int64_t>(rng)); break;
    case 4: both(pick<std::uint8_t>(rng)); break;
    case 5: both(pick<std::uint16_t>(rng)); break;
    case 6: both(pick<std::uint32_t>(rng)); break;
    case 7: both(pick<std::uint64_t>(rng)); break;
    case 8: both(pick<float>(rng)); break;
    default: both(pick<double>(rng)); break;
  }
}

TEST(StVmNativeRandom, RandomProgramsRunAsTheInterpreterRunsThem) {
  const char* env = std::getenv("NATIVE_RANDOM_N");
  const int programs = env ? std::atoi(env) : 40;
  const char* s0 = std::getenv("NATIVE_RANDOM_SEED");
  const std::uint64_t seed0 = s0 ? std::strtoull(s0, nullptr, 10) : 1;
  int compiled = 0, reg_loops = 0;
  for (int prog = 0; prog < programs; ++prog) {
    Gen g(seed0 * 1000003 + static_cast<std::uint64_t>(prog));
    const std::string src = g.program();
    StRun native({src}, "P", 10'000'000, vm::Engine::Native);
    StRun interp({src}, "P", 10'000'000, vm::Engine::Interpreter);
    if (!native.ok()) continue;  // a constant the generator made out of its type's range
    ++compiled;
    reg_loops += static_cast<int>(vm::native_register_loops(*native.module));
    std::mt19937_64 rng(prog);
    for (int scan = 0; scan < 30; ++scan) {
      for (int t = 0; t < kNT; ++t)
        for (const std::string& n : {std::string("v") + std::to_string(t) + "_" + std::to_string(rng() % 3),
                                     std::string("c") + std::to_string(t), std::string("kk") + std::to_string(t)})
          if (rng() % 2) set_random(native, interp, rng, n, t);
      for (int w = 0; w < 4; ++w) {
        const std::uint64_t v = rng() % 3 == 0 ? ~0ull : rng();
        const std::uint64_t mask = w == 3 ? ~0ull : (1ull << (8 << w)) - 1;
        native.set<std::uint64_t>("w" + std::to_string(w), v & mask);
        interp.set<std::uint64_t>("w" + std::to_string(w), v & mask);
      }
      const std::int64_t budget = scan % 3 == 0 ? static_cast<std::int64_t>(rng() % 50) : 3000;
      native.budget = interp.budget = budget;
      const bool a = native.scan(), b = interp.scan();
      bool same = a == b && native.fault_texts() == interp.fault_texts() &&
                  (native.instance->stopped() == nullptr) == (interp.instance->stopped() == nullptr) &&
                  (native.instance->stopped() == nullptr ||
                   std::string(native.instance->stopped()) == interp.instance->stopped());
      // A reference cell (a VAR_IN_OUT, an FB passed through one) holds an
      // address: compared as an offset from its frame.
      std::uint32_t bad = 0;
      const Cell* fa = native.instance->frame();
      const Cell* fb = interp.instance->frame();
      for (std::uint32_t k = 0; k < native.instance->frame_cells() && same; ++k)
        if (!same_cell(fa[k].raw, fb[k].raw) &&
            fa[k].raw - reinterpret_cast<std::uintptr_t>(fa) != fb[k].raw - reinterpret_cast<std::uintptr_t>(fb))
          same = false, bad = k;
      if (!same) {
        ADD_FAILURE() << "program " << prog << " seed " << seed0 << " scan " << scan << " ran " << a << b
                      << " cell " << bad << " " << fa[bad].raw << " vs " << fb[bad].raw << "\n" << src;
        return;
      }
    }
  }
  EXPECT_GE(compiled, programs * 3 / 4);
#if defined(__x86_64__)
  EXPECT_GE(reg_loops, programs) << "the programs' loops keep cells in registers";
#endif
}

}  // namespace
}  // namespace syncplc::st::testing

