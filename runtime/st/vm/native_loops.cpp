// Loops whose cells live in registers in native code (native_loops.hpp).
#include "runtime/st/vm/native_loops.hpp"

#include <algorithm>
#include <map>

namespace syncplc::st::vm {

namespace {

// How an instruction's template uses an operand cell (native_x64.cpp):
// Real: as an LREAL value; Word: as an integer; Bits: its 64 bits copied or
// tested (either kind of register holds them); Frame: it must stay in the
// frame (a REAL, or an element of an array the code indexes).
enum class Use { Real, Word, Bits, Frame };

struct UsedCell {
  std::uint32_t cell;
  Use use;
};

bool family_member(Op op, Op first, int members, Num* n) {
  const int k = static_cast<int>(op) - static_cast<int>(first);
  if (k < 0 || k >= members) return false;
  *n = static_cast<Num>(k);
  return true;
}

Use use_of(Num n) { return n == Num::F64 ? Use::Real : n == Num::F32 ? Use::Frame : Use::Word; }

// The operands of a templated instruction and their uses; array elements an
// index reaches in `frame_only`.
void operand_uses(const Module& m, const Insn& i, std::vector<UsedCell>* out,
              std::vector<std::pair<std::uint32_t, std::uint64_t>>* frame_only) {
  Num n{};
  switch (i.op) {
    case Op::HALT: case Op::JMP: case Op::JMPB: return;
    case Op::JZ: case Op::JNZ: out->push_back({i.a, Use::Bits}); return;
    case Op::MOV: case Op::NOT_BOOL: case Op::GETBIT:
      out->push_back({i.a, Use::Bits});
      out->push_back({i.b, Use::Bits});
      return;
    case Op::AND: case Op::OR: case Op::XOR:
      out->push_back({i.a, Use::Bits});
      out->push_back({i.b, Use::Bits});
      out->push_back({i.c, Use::Bits});
      return;
    default: break;
  }
  for (Op first : {Op::ADD_I8, Op::SUB_I8, Op::MUL_I8, Op::CLAMP_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      for (std::uint32_t k : {i.a, i.b, i.c}) out->push_back({k, use_of(n)});
      return;
    }
  for (Op first : {Op::MULADD_I8, Op::ADDMUL_I8, Op::MULSUB_I8, Op::SUBMUL_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      for (std::uint32_t k : {i.a, i.b, i.c, i.d}) out->push_back({k, use_of(n)});
      return;
    }
  for (Op first : {Op::EQ_I8, Op::NE_I8, Op::LT_I8, Op::LE_I8, Op::GT_I8, Op::GE_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      out->push_back({i.a, Use::Bits});
      out->push_back({i.b, use_of(n)});
      out->push_back({i.c, use_of(n)});
      return;
    }
  for (Op first : {Op::JNLT_I8, Op::JNLE_I8, Op::JNGT_I8, Op::JNGE_I8, Op::JNEQ_I8, Op::JNNE_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      out->push_back({i.a, use_of(n)});
      out->push_back({i.b, use_of(n)});
      return;
    }
  if (family_member(i.op, Op::FOR_INC_I8, 8, &n)) {
    out->push_back({i.a, Use::Word});
    out->push_back({i.b, Use::Word});
    return;
  }
  if (family_member(i.op, Op::LDX_I8, 8, &n)) {
    out->push_back({i.a, Use::Bits});
    out->push_back({i.c, Use::Word});
    frame_only->emplace_back(i.b, m.indexes[i.d].count);
    return;
  }
  if (family_member(i.op, Op::STX_I8, 8, &n)) {
    out->push_back({i.b, Use::Bits});
    out->push_back({i.c, Use::Word});
    frame_only->emplace_back(i.a, m.indexes[i.d].count);
    return;
  }
  for (Op first : {Op::DIV_I8, Op::MOD_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      for (std::uint32_t k : {i.a, i.b, i.c}) out->push_back({k, use_of(n)});
      return;
    }
  for (Op first : {Op::WIDEN_TO_I16_I8, Op::WIDEN_TO_I32_I8, Op::WIDEN_TO_I64_I8})
    if (family_member(i.op, first, kNumCount, &n)) {
      out->push_back({i.a, Use::Word});
      out->push_back({i.b, use_of(n)});
      return;
    }
  if (family_member(i.op, Op::WIDEN_TO_F64_I8, kNumCount, &n)) {
    out->push_back({i.a, Use::Real});
    out->push_back({i.b, use_of(n)});
    return;
  }
  // An instruction the templates do not know: nothing may stay in a register.
  out->push_back({i.a, Use::Frame});
}

bool is_backward_jump(Op op) {
  return op == Op::JMPB || (op >= Op::FOR_INC_I8 && op <= Op::FOR_INC_U64) ||
         (op >= Op::FOR_NEXT_I8 && op <= Op::FOR_NEXT_U64);
}

// Whether instruction i may jump to t (its d or a table's targets).
bool jumps_into(const Module& m, const Insn& i, std::uint32_t lo, std::uint32_t hi) {
  auto inside = [&](std::uint32_t t) { return t > lo && t <= hi; };
  const Op op = i.op;
  if (op == Op::SWITCH) {
    const JumpTable& t = m.tables[i.b];
    if (inside(t.otherwise)) return true;
    return std::any_of(t.targets.begin(), t.targets.end(), inside);
  }
  const bool jump = op == Op::JMP || op == Op::JMPB || op == Op::JZ || op == Op::JNZ ||
                    (op >= Op::JNLT_I8 && op <= Op::JNNE_F64) || (op >= Op::FOR_ENTER_I8 && op <= Op::FOR_NEXT_U64) ||
                    (op >= Op::FOR_INC_I8 && op <= Op::FOR_INC_U64);
  return jump && inside(i.d);
}

}  // namespace

std::vector<RegisterLoop> register_loops(const Module& m, const CompiledPou& p,
                                         bool (*templated)(const Module&, const Insn&), std::size_t max_reals,
                                         std::size_t max_words) {
  std::vector<RegisterLoop> loops;
  const auto n = static_cast<std::uint32_t>(p.code.size());
  for (std::uint32_t e = 0; e < n; ++e) {
    const Insn& back = p.code[e];
    if (!is_backward_jump(back.op) || back.d > e) continue;
    const std::uint32_t h = back.d;
    bool ok = true;
    for (std::uint32_t pc = h; pc <= e && ok; ++pc)
      ok = templated(m, p.code[pc]) && (pc == e || !is_backward_jump(p.code[pc].op));
    for (std::uint32_t pc = 0; pc < n && ok; ++pc)
      if (pc < h || pc > e) ok = !jumps_into(m, p.code[pc], h, e);
    if (!ok) continue;

    std::map<std::uint32_t, std::pair<int, int>> uses;  // cell -> (count, kinds: 1 Real, 2 Word, 4 Frame)
    std::vector<UsedCell> ops;
    std::vector<std::pair<std::uint32_t, std::uint64_t>> arrays;
    for (std::uint32_t pc = h; pc <= e; ++pc) operand_uses(m, p.code[pc], &ops, &arrays);
    for (const UsedCell& o : ops) {
      auto& u = uses[o.cell];
      ++u.first;
      u.second |= o.use == Use::Real ? 1 : o.use == Use::Word ? 2 : o.use == Use::Frame ? 4 : 0;
    }
    std::vector<std::pair<int, std::uint32_t>> reals, words;  // (-count, cell): the most used first
    for (const auto& [cell, u] : uses) {
      const bool in_array = std::any_of(arrays.begin(), arrays.end(), [&, c = cell](const auto& a) {
        return c >= a.first && c - a.first < a.second;
      });
      if (in_array || (u.second & 4) || u.second == 3) continue;
      (u.second == 1 ? reals : words).emplace_back(-u.first, cell);
    }
    std::sort(reals.begin(), reals.end());
    std::sort(words.begin(), words.end());
    RegisterLoop loop{h, e, {}, {}};
    for (std::size_t k = 0; k < reals.size() && k < max_reals; ++k) loop.reals.push_back(reals[k].second);
    for (std::size_t k = 0; k < words.size() && k < max_words; ++k) loop.words.push_back(words[k].second);
    if (!loop.reals.empty() || !loop.words.empty()) loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace syncplc::st::vm
