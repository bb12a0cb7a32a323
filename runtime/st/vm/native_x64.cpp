// Native code for compiled ST on x86-64: a baseline compiler from the VM's
// instructions (code.hpp) to machine code, made at load with Xbyak (Debian's
// libxbyak-dev) into memory that is written, then made read+execute (never
// both). docs/st.md, "How compiled ST runs", gives the reasons.
//
// One template per instruction, in the instruction's order: no dispatch, the
// frame's base in a register and every operand a constant displacement from
// it. An instruction with no template here, and every rare path of one that
// has (an index out of bounds, the loop budget running out), calls step()
// (interp.cpp), which runs that one instruction by the interpreter's own
// handler and says where to go on; so each instruction's meaning is written
// once, and native code and the interpreter give the same bits.
//
// Registers while a POU's code runs (all callee-saved, so step() keeps them):
//   rbx  the frame (cell k at [rbx + 8k])
//   r12  the Vm
//   r13  the loop budget (Vm::budget, written back around every step())
//   r14  the CompiledPou
//   r15  the table of each instruction's code address (the targets of step())
// and, inside a loop native_loops.cpp picked, its cells: LREALs in xmm4 ..
// xmm15, integers and bits in rsi, rdi, r8 .. r11, read at its head, written
// back on every way out and around every call of step(). Templates use rax,
// rcx, rdx, xmm0 and xmm1 as scratch.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>

#include "runtime/st/vm/native_loops.hpp"
#include "runtime/st/vm/strings_op.hpp"
#include "runtime/st/vm/vm.hpp"

#if defined(__x86_64__) && defined(SYNCPLC_HAVE_XBYAK)
#define SYNCPLC_ST_NATIVE 1
#include <xbyak/xbyak.h>
#endif

namespace syncplc::st::vm {

#if SYNCPLC_ST_NATIVE
namespace {

using namespace Xbyak;
using namespace Xbyak::util;

constexpr int kBudget = static_cast<int>(offsetof(Vm, budget));

bool is_signed(Num n) { return n <= Num::I64; }
int width(Num n) {  // bytes
  switch (n) {
    case Num::I8: case Num::U8: return 1;
    case Num::I16: case Num::U16: return 2;
    case Num::I32: case Num::U32: case Num::F32: return 4;
    default: return 8;
  }
}
// The member of family `first` (ADD_I8) that `op` is, and its type; false
// when op is not in that family.
bool in_family(Op op, Op first, int members, Num* n) {
  const int k = static_cast<int>(op) - static_cast<int>(first);
  if (k < 0 || k >= members) return false;
  *n = static_cast<Num>(k);
  return true;
}

bool calls_out(const Insn& i);

// Whether an instruction has a template (Emitter::insn emits one exactly
// for these).
bool templated(const Module&, const Insn& i) {
  Num n{};
  switch (i.op) {
    case Op::HALT: case Op::JMP: case Op::JMPB: case Op::JZ: case Op::JNZ: case Op::MOV:
    case Op::AND: case Op::OR: case Op::XOR: case Op::NOT_BOOL:
      return true;
    case Op::GETBIT: return i.c <= 63;
    default: break;
  }
  for (Op first : {Op::ADD_I8, Op::SUB_I8, Op::MUL_I8, Op::EQ_I8, Op::NE_I8, Op::LT_I8, Op::LE_I8, Op::GT_I8,
                   Op::GE_I8, Op::JNLT_I8, Op::JNLE_I8, Op::JNGT_I8, Op::JNGE_I8, Op::JNEQ_I8, Op::JNNE_I8,
                   Op::MULADD_I8, Op::ADDMUL_I8, Op::MULSUB_I8, Op::SUBMUL_I8, Op::CLAMP_I8})
    if (in_family(i.op, first, kNumCount, &n)) return true;
  if (in_family(i.op, Op::FOR_INC_I8, 8, &n)) return true;
  if (in_family(i.op, Op::LDX_I8, 8, &n) || in_family(i.op, Op::STX_I8, 8, &n)) return n != Num::U64;
  if (in_family(i.op, Op::WIDEN_TO_F64_I8, kNumCount, &n)) return n != Num::U64 && n != Num::F64;
  for (Op first : {Op::WIDEN_TO_I16_I8, Op::WIDEN_TO_I32_I8, Op::WIDEN_TO_I64_I8})
    if (in_family(i.op, first, kNumCount, &n)) return n != Num::F32 && n != Num::F64;
  if (in_family(i.op, Op::DIV_I8, kNumCount, &n)) return true;
  if (in_family(i.op, Op::MOD_I8, kNumCount, &n)) return n != Num::F32 && n != Num::F64;
  return calls_out(i);
}

// Templates that call a function of the runtime (as the interpreter's
// handler does) rather than compute in place: the call may clobber every
// caller-saved register and reach any cell, so no loop around one keeps
// cells in registers; and a SWITCH, whose targets the loop analysis leaves
// alone.
bool calls_out(const Insn& i) {
  return i.op == Op::STRFN || i.op == Op::MATH1 || i.op == Op::MATH2 || i.op == Op::CALL_FB || i.op == Op::SWITCH;
}

bool loop_safe(const Module& m, const Insn& i) { return templated(m, i) && !calls_out(i); }

class Emitter : public CodeGenerator {
 public:
  Emitter(const Module& m, const CompiledPou& p, std::size_t bytes)
      : CodeGenerator(bytes, DontSetProtectRWE), m_(m), p_(p), at_(p.code.size()), slow_(p.code.size()) {}

  void emit() {
    prologue();
    const auto n = static_cast<std::uint32_t>(p_.code.size());
    loops_ = register_loops(m_, p_, &loop_safe, std::size(kRealRegs), std::size(kWordRegs));
    heads_ = std::vector<Label>(loops_.size());
    std::vector<int> loop_at(n, -1);  // pc -> its loop's index in loops_
    for (std::size_t k = 0; k < loops_.size(); ++k)
      for (std::uint32_t pc = loops_[k].head; pc <= loops_[k].end; ++pc) loop_at[pc] = static_cast<int>(k);
    std::vector<bool> needs_slow(n, false);
    for (std::uint32_t pc = 0; pc < n; ++pc) {
      L(at_[pc]);
      if (loop_at[pc] >= 0 && loops_[loop_at[pc]].head == pc) {
        enter(loops_[loop_at[pc]]);
        load_all();
        L(*inner_head_);
      }
      if (!insn(pc, p_.code[pc])) step_call(pc);
      else if (slow_used_) needs_slow[pc] = true;
      slow_used_ = false;
      if (loop_ && pc == loop_->end) leave();
    }
    // The code never falls off its end (the generator ends every POU with
    // HALT); were it to, it returns as HALT does.
    jmp(exit_ok_, T_NEAR);
    for (std::uint32_t pc = 0; pc < n; ++pc)
      if (needs_slow[pc]) {
        L(slow_[pc]);
        if (loop_at[pc] < 0) {
          step_call(pc);
          jmp(at_[pc + 1 < n ? pc + 1 : pc], T_NEAR);  // unreachable for the last (HALT)
          continue;
        }
        // In a loop: the frame gets the registers' values for step() and
        // the registers what step() left in the frame.
        enter(loops_[loop_at[pc]]);
        store_all();
        step_call(pc, false);
        load_all();
        cmp(eax, pc + 1);
        jne(after_step_, T_NEAR);
        jmp(at_[pc + 1], T_NEAR);
        loop_ = nullptr;
        reals_.clear();
        words_.clear();
      }
    // Where step() did not go on to the next instruction.
    L(after_step_);
    mov(eax, eax);  // a uint32 result: rax's high half is not defined
    cmp(eax, kStepStopped);
    je(exit_stop_, T_NEAR);
    cmp(eax, kStepHalted);
    je(exit_ok_, T_NEAR);
    jmp(qword[r15 + rax * 8]);
    L(exit_ok_);
    mov(qword[r12 + kBudget], r13);
    mov(eax, 1);
    epilogue();
    L(exit_stop_);
    xor_(eax, eax);  // step() left the budget in the Vm
    epilogue();
    align(8);
    L(table_);
    for (std::uint32_t pc = 0; pc < n; ++pc) putL(at_[pc]);
    for (auto& [t, label] : switch_tables_) {
      L(label);
      for (std::uint32_t to : m_.tables[t].targets) putL(at_[to]);
    }
  }

 private:
  const Module& m_;
  const CompiledPou& p_;
  std::vector<Label> at_, slow_;
  Label after_step_, exit_ok_, exit_stop_, table_;
  bool slow_used_ = false;
  std::map<std::uint32_t, Label> switch_tables_;  // a SWITCH's jump table (Module::tables index) in the code

  // The loop being emitted, its cells' registers, and where its ways out
  // write them back.
  static constexpr int kRealRegs[] = {4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};  // xmm4 .. xmm15
  static constexpr int kWordRegs[] = {Xbyak::Operand::RSI, Xbyak::Operand::RDI, Xbyak::Operand::R8,
                                      Xbyak::Operand::R9,  Xbyak::Operand::R10, Xbyak::Operand::R11};
  std::vector<RegisterLoop> loops_;
  const RegisterLoop* loop_ = nullptr;
  std::vector<std::pair<std::uint32_t, Xmm>> reals_;
  std::vector<std::pair<std::uint32_t, Reg64>> words_;
  std::vector<Label> heads_;  // per loop: its head past the loads
  Label* inner_head_ = nullptr;
  std::map<std::uint32_t, Label> exits_;

  void enter(const RegisterLoop& l) {
    loop_ = &l;
    reals_.clear();
    words_.clear();
    for (std::size_t k = 0; k < l.reals.size(); ++k) reals_.emplace_back(l.reals[k], Xmm(kRealRegs[k]));
    for (std::size_t k = 0; k < l.words.size(); ++k) words_.emplace_back(l.words[k], Reg64(kWordRegs[k]));
    inner_head_ = &heads_[static_cast<std::size_t>(&l - loops_.data())];
    exits_.clear();
  }
  // After the loop's last instruction (a jump back: nothing falls through).
  void leave() {
    for (auto& [to, label] : exits_) {
      L(label);
      store_all();
      jmp(at_[to], T_NEAR);
    }
    exits_.clear();
    loop_ = nullptr;
    reals_.clear();
    words_.clear();
  }
  void load_all() {
    for (const auto& [k, x] : reals_) movsd(x, cell(k));
    for (const auto& [k, g] : words_) mov(g, cell(k));
  }
  void store_all() {
    for (const auto& [k, x] : reals_) movsd(cell(k), x);
    for (const auto& [k, g] : words_) mov(cell(k), g);
  }
  const Xmm* real_reg(std::uint32_t k) const {
    for (const auto& [c, x] : reals_)
      if (c == k) return &x;
    return nullptr;
  }
  const Reg64* word_reg(std::uint32_t k) const {
    for (const auto& [c, g] : words_)
      if (c == k) return &g;
    return nullptr;
  }
  // Where a jump to pc `d` goes. Inside the loop it goes to d itself (to
  // the head past the head's loads). Out of the loop it goes through a
  // trampoline of its own (exits_) that first writes the registers back to
  // the frame, then jumps to d.
  const Label& target(std::uint32_t d) {
    if (!loop_) return at_[d];
    if (d == loop_->head) return *inner_head_;
    if (d > loop_->head && d <= loop_->end) return at_[d];
    return exits_[d];
  }
  // A cell's 64 bits to or from a general register, wherever the cell is.
  void raw_load(const Reg64& r, std::uint32_t k) {
    if (const Reg64* g = word_reg(k)) mov(r, *g);
    else if (const Xmm* x = real_reg(k)) movq(r, *x);
    else mov(r, cell(k));
  }
  void raw_store(std::uint32_t k, const Reg64& r) {
    if (const Reg64* g = word_reg(k)) mov(*g, r);
    else if (const Xmm* x = real_reg(k)) movq(*x, r);
    else mov(cell(k), r);
  }

  Address cell(std::uint32_t k) const { return qword[rbx + static_cast<int>(k) * 8]; }
  static int disp(std::uint32_t k) { return static_cast<int>(k) * 8; }

  void prologue() {
    // A null frame (an FB called through a VAR_IN_OUT nothing bound: a
    // PROGRAM the project instances has no caller to bind it) runs nothing,
    // as the interpreter's exec() does with one, instead of loading cells
    // from address 0.
    Label frame;
    test(rsi, rsi);
    jnz(frame);
    mov(eax, 1);
    ret();
    L(frame);
    push(rbx);
    push(r12);
    push(r13);
    push(r14);
    push(r15);  // five pushes: rsp is 16-aligned again for the calls
    mov(r12, rdi);
    mov(rbx, rsi);
    mov(r13, qword[r12 + kBudget]);
    mov(r14, reinterpret_cast<std::uintptr_t>(&p_));
    lea(r15, ptr[rip + table_]);
  }
  void epilogue() {
    pop(r15);
    pop(r14);
    pop(r13);
    pop(r12);
    pop(rbx);
    ret();
  }

  // The instruction at pc by the interpreter; on to pc + 1 when that is
  // where it goes.
  void step_call(std::uint32_t pc, bool go_on = true) {
    mov(qword[r12 + kBudget], r13);
    mov(rdi, r12);
    mov(rsi, r14);
    mov(rdx, rbx);
    mov(ecx, pc);
    mov(rax, reinterpret_cast<std::uintptr_t>(&step));
    call(rax);
    mov(r13, qword[r12 + kBudget]);
    if (!go_on) return;
    cmp(eax, pc + 1);
    jne(after_step_, T_NEAR);
  }
  // The rare path of a templated instruction: step() runs it.
  const Label& slow(std::uint32_t pc) {
    slow_used_ = true;
    return slow_[pc];
  }

  // A cell of integer type n into r (sign- or zero-extended to 64 bits), as
  // Cell::get reads its low bytes.
  void load_int(const Reg64& r, std::uint32_t k, Num n) {
    if (const Reg64* g = word_reg(k)) {
      switch (n) {
        case Num::I8: movsx(r, g->cvt8()); break;
        case Num::I16: movsx(r, g->cvt16()); break;
        case Num::I32: movsxd(r, g->cvt32()); break;
        case Num::U8: movzx(r.cvt32(), g->cvt8()); break;
        case Num::U16: movzx(r.cvt32(), g->cvt16()); break;
        case Num::U32: mov(r.cvt32(), g->cvt32()); break;
        default: mov(r, *g); break;
      }
      return;
    }
    const int d = disp(k);
    switch (n) {
      case Num::I8: movsx(r, byte[rbx + d]); break;
      case Num::I16: movsx(r, word[rbx + d]); break;
      case Num::I32: movsxd(r, dword[rbx + d]); break;
      case Num::U8: movzx(r.cvt32(), byte[rbx + d]); break;
      case Num::U16: movzx(r.cvt32(), word[rbx + d]); break;
      case Num::U32: mov(r.cvt32(), dword[rbx + d]); break;
      default: mov(r, qword[rbx + d]); break;
    }
  }
  // r's low bytes of n's width, the rest zero, into cell k (as Cell::set).
  void store_int(std::uint32_t k, const Reg64& r, Num n) {
    switch (width(n)) {
      case 1: movzx(r.cvt32(), r.cvt8()); break;
      case 2: movzx(r.cvt32(), r.cvt16()); break;
      case 4: mov(r.cvt32(), r.cvt32()); break;
      default: break;
    }
    if (const Reg64* g = word_reg(k)) mov(*g, r);
    else mov(cell(k), r);
  }
  // A REAL cell never lives in a register (native_loops.cpp); an LREAL may.
  void load_real(const Xmm& x, std::uint32_t k, Num n) {
    if (n == Num::F32) movss(x, dword[rbx + disp(k)]);
    else if (const Xmm* r = real_reg(k)) movapd(x, *r);
    else movsd(x, qword[rbx + disp(k)]);
  }
  void store_real(std::uint32_t k, const Xmm& x, Num n) {
    if (const Xmm* r = n == Num::F64 ? real_reg(k) : nullptr) {
      movapd(*r, x);
    } else if (n == Num::F32) {
      movd(eax, x);  // zero-extended: the cell's high half is zero
      mov(cell(k), rax);
    } else {
      movsd(cell(k), x);
    }
  }
  void real_op(char op, const Xmm& x, std::uint32_t k, Num n) {
    if (const Xmm* r = n == Num::F64 ? real_reg(k) : nullptr) return real_op(op, x, *r, n);
    const bool f32 = n == Num::F32;
    const Address a = f32 ? dword[rbx + disp(k)] : qword[rbx + disp(k)];
    switch (op) {
      case '+': f32 ? addss(x, a) : addsd(x, a); break;
      case '/': f32 ? divss(x, a) : divsd(x, a); break;
      case '-': f32 ? subss(x, a) : subsd(x, a); break;
      default: f32 ? mulss(x, a) : mulsd(x, a); break;
    }
  }
  void real_op(char op, const Xmm& x, const Xmm& y, Num n) {
    const bool f32 = n == Num::F32;
    switch (op) {
      case '+': f32 ? addss(x, y) : addsd(x, y); break;
      case '/': f32 ? divss(x, y) : divsd(x, y); break;
      case '-': f32 ? subss(x, y) : subsd(x, y); break;
      default: f32 ? mulss(x, y) : mulsd(x, y); break;
    }
  }
  void ucomi(const Xmm& x, std::uint32_t k, Num n) {
    if (const Xmm* r = n == Num::F64 ? real_reg(k) : nullptr) ucomisd(x, *r);
    else if (n == Num::F32) ucomiss(x, dword[rbx + disp(k)]);
    else ucomisd(x, qword[rbx + disp(k)]);
  }

  enum class Rel { Lt, Le, Gt, Ge, Eq, Ne };

  // Flags for "x rel y" after an integer cmp(x, y): the jump taken when it
  // holds.
  void jump_if(Rel r, bool sgn, const Label& to) {
    switch (r) {
      case Rel::Lt: sgn ? jl(to, T_NEAR) : jb(to, T_NEAR); break;
      case Rel::Le: sgn ? jle(to, T_NEAR) : jbe(to, T_NEAR); break;
      case Rel::Gt: sgn ? jg(to, T_NEAR) : ja(to, T_NEAR); break;
      case Rel::Ge: sgn ? jge(to, T_NEAR) : jae(to, T_NEAR); break;
      case Rel::Eq: je(to, T_NEAR); break;
      case Rel::Ne: jne(to, T_NEAR); break;
    }
  }
  void set_if(Rel r, bool sgn, const Reg8& b) {
    switch (r) {
      case Rel::Lt: sgn ? setl(b) : setb(b); break;
      case Rel::Le: sgn ? setle(b) : setbe(b); break;
      case Rel::Gt: sgn ? setg(b) : seta(b); break;
      case Rel::Ge: sgn ? setge(b) : setae(b); break;
      case Rel::Eq: sete(b); break;
      case Rel::Ne: setne(b); break;
    }
  }
  static Rel negated(Rel r) {
    switch (r) {
      case Rel::Lt: return Rel::Ge;
      case Rel::Le: return Rel::Gt;
      case Rel::Gt: return Rel::Le;
      case Rel::Ge: return Rel::Lt;
      case Rel::Eq: return Rel::Ne;
      default: return Rel::Eq;
    }
  }

  // Flags of a real comparison "cell x rel cell y" as C++ computes it (false
  // when either is NaN): ucomis sets CF=ZF=PF=1 for unordered, so every
  // relation is tested as "above" or "above or equal" of the right pair.
  // Leaves al = 1 when it holds.
  void real_relation(Rel r, std::uint32_t x, std::uint32_t y, Num n) {
    switch (r) {
      case Rel::Gt: load_real(xmm0, x, n); ucomi(xmm0, y, n); seta(al); break;
      case Rel::Ge: load_real(xmm0, x, n); ucomi(xmm0, y, n); setae(al); break;
      case Rel::Lt: load_real(xmm0, y, n); ucomi(xmm0, x, n); seta(al); break;
      case Rel::Le: load_real(xmm0, y, n); ucomi(xmm0, x, n); setae(al); break;
      case Rel::Eq: load_real(xmm0, x, n); ucomi(xmm0, y, n); sete(al); setnp(cl); and_(al, cl); break;
      case Rel::Ne: load_real(xmm0, x, n); ucomi(xmm0, y, n); setne(al); setp(cl); or_(al, cl); break;
    }
  }

  void compare_set(Rel r, const Insn& i, Num n) {  // a := b rel c
    if (n == Num::F32 || n == Num::F64) {
      real_relation(r, i.b, i.c, n);
    } else {
      load_int(rax, i.b, n);
      load_int(rcx, i.c, n);
      cmp(rax, rcx);
      set_if(r, is_signed(n), al);
    }
    movzx(eax, al);
    raw_store(i.a, rax);
  }
  void compare_jump(Rel r, const Insn& i, Num n) {  // if !(a rel b) goto d
    if (n == Num::F32 || n == Num::F64) {
      // Not above / below: taken also when unordered (CF = 1), as !(x > y).
      const Label& to = target(i.d);
      switch (r) {
        case Rel::Gt: load_real(xmm0, i.a, n); ucomi(xmm0, i.b, n); jbe(to, T_NEAR); break;
        case Rel::Ge: load_real(xmm0, i.a, n); ucomi(xmm0, i.b, n); jb(to, T_NEAR); break;
        case Rel::Lt: load_real(xmm0, i.b, n); ucomi(xmm0, i.a, n); jbe(to, T_NEAR); break;
        case Rel::Le: load_real(xmm0, i.b, n); ucomi(xmm0, i.a, n); jb(to, T_NEAR); break;
        case Rel::Eq: load_real(xmm0, i.a, n); ucomi(xmm0, i.b, n); jne(to, T_NEAR); jp(to, T_NEAR); break;
        case Rel::Ne: {
          Label differ;
          load_real(xmm0, i.a, n);
          ucomi(xmm0, i.b, n);
          jne(differ, T_NEAR);
          jp(differ, T_NEAR);
          jmp(to, T_NEAR);
          L(differ);
          break;
        }
      }
    } else {
      load_int(rax, i.a, n);
      load_int(rcx, i.b, n);
      cmp(rax, rcx);
      jump_if(negated(r), is_signed(n), target(i.d));
    }
  }

  void arith(char op, const Insn& i, Num n) {  // a := b op c
    if (n == Num::F32 || n == Num::F64) {
      load_real(xmm0, i.b, n);
      real_op(op, xmm0, i.c, n);
      store_real(i.a, xmm0, n);
      return;
    }
    load_int(rax, i.b, n);
    load_int(rcx, i.c, n);
    switch (op) {  // modulo 2^64, then cut to n's width: the wrap in n's type
      case '+': add(rax, rcx); break;
      case '-': sub(rax, rcx); break;
      default: imul(rax, rcx); break;
    }
    store_int(i.a, rax, n);
  }

  // MULADD a := b * c + d, ADDMUL a := d + b * c, MULSUB a := b * c - d,
  // SUBMUL a := d - b * c: the product rounded first, as the two operations.
  void fused(int form, const Insn& i, Num n) {
    if (n == Num::F32 || n == Num::F64) {
      load_real(xmm0, i.b, n);
      real_op('*', xmm0, i.c, n);
      switch (form) {
        case 0: real_op('+', xmm0, i.d, n); store_real(i.a, xmm0, n); break;
        case 1: load_real(xmm1, i.d, n); real_op('+', xmm1, xmm0, n); store_real(i.a, xmm1, n); break;
        case 2: real_op('-', xmm0, i.d, n); store_real(i.a, xmm0, n); break;
        default: load_real(xmm1, i.d, n); real_op('-', xmm1, xmm0, n); store_real(i.a, xmm1, n); break;
      }
      return;
    }
    load_int(rax, i.b, n);
    load_int(rcx, i.c, n);
    imul(rax, rcx);
    load_int(rcx, i.d, n);
    switch (form) {
      case 0: case 1: add(rax, rcx); break;
      case 2: sub(rax, rcx); break;
      default: sub(rcx, rax); mov(rax, rcx); break;
    }
    store_int(i.a, rax, n);
  }

  // FOR with the step 1: if a < b then a := a + 1, count, goto d.
  void for_inc(std::uint32_t pc, const Insn& i, Num n) {
    load_int(rax, i.a, n);
    load_int(rcx, i.b, n);
    cmp(rax, rcx);
    jump_if(Rel::Ge, is_signed(n), target(pc + 1));
    test(r13, r13);
    jle(slow(pc), T_NEAR);  // the budget is spent: step() stops the chain
    dec(r13);
    add(rax, 1);
    store_int(i.a, rax, n);
    jmp(target(i.d), T_NEAR);
  }

  // rcx := the checked element offset of index cell c (array index d); out
  // of bounds to step(), which faults. (U64 indices, saturated, have no
  // template.)
  void element(std::uint32_t pc, const Insn& i, Num n) {
    const IndexCheck& k = m_.indexes[i.d];
    load_int(rcx, i.c, n);
    if (k.low >= std::numeric_limits<std::int32_t>::min() && k.low <= std::numeric_limits<std::int32_t>::max()) {
      sub(rcx, static_cast<std::uint32_t>(static_cast<std::int32_t>(k.low)));
    } else {
      mov(rdx, static_cast<std::uint64_t>(k.low));
      sub(rcx, rdx);
    }
    if (k.count <= static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      cmp(rcx, static_cast<std::uint32_t>(k.count));
    } else {
      mov(rdx, k.count);
      cmp(rcx, rdx);
    }
    jae(slow(pc), T_NEAR);
  }

  // The clamping IF: d = 0 tests the upper bound c first, d = 1 the lower b.
  void clamp(const Insn& i, Num n) {
    Label to_c, to_b, done;
    const bool real = n == Num::F32 || n == Num::F64;
    auto over = [&] {  // a > c
      if (real) { load_real(xmm0, i.a, n); ucomi(xmm0, i.c, n); ja(to_c, T_NEAR); }
      else { load_int(rax, i.a, n); load_int(rcx, i.c, n); cmp(rax, rcx); jump_if(Rel::Gt, is_signed(n), to_c); }
    };
    auto under = [&] {  // a < b
      if (real) { load_real(xmm0, i.b, n); ucomi(xmm0, i.a, n); ja(to_b, T_NEAR); }
      else { load_int(rax, i.a, n); load_int(rcx, i.b, n); cmp(rax, rcx); jump_if(Rel::Lt, is_signed(n), to_b); }
    };
    if (i.d == 0) { over(); under(); }
    else { under(); over(); }
    jmp(done, T_NEAR);
    L(to_c);
    raw_load(rax, i.c);
    raw_store(i.a, rax);
    jmp(done, T_NEAR);
    L(to_b);
    raw_load(rax, i.b);
    raw_store(i.a, rax);
    L(done);
  }

  // DIV and MOD. Reals: IEEE division (MOD of reals has no template). An
  // integer divisor of 0 (a fault) or -1 (the most negative value wraps)
  // goes to step(); otherwise the hardware's division truncates toward zero
  // and its remainder has the dividend's sign, as C++'s.
  void divide(std::uint32_t pc, const Insn& i, Num n, bool remainder) {
    if (n == Num::F32 || n == Num::F64) {
      load_real(xmm0, i.b, n);
      real_op('/', xmm0, i.c, n);
      store_real(i.a, xmm0, n);
      return;
    }
    load_int(rax, i.b, n);
    load_int(rcx, i.c, n);
    test(rcx, rcx);
    jz(slow(pc), T_NEAR);
    if (is_signed(n)) {
      cmp(rcx, -1);
      je(slow(pc), T_NEAR);
      cqo();
      idiv(rcx);
    } else {
      xor_(edx, edx);
      div(rcx);
    }
    store_int(i.a, remainder ? rdx : rax, n);
  }

  // The templates that call the runtime function the interpreter's handler
  // calls, directly.
  bool call_out(const Insn& i) {
    switch (i.op) {
      case Op::STRFN:
        mov(rdi, r12);
        mov(rsi, rbx);
        mov(rdx, reinterpret_cast<std::uintptr_t>(&m_.strings[i.d]));
        mov(rax, reinterpret_cast<std::uintptr_t>(&string_op));
        call(rax);
        return true;
      case Op::MATH1:
        mov(rdi, cell(i.b));
        mov(rax, reinterpret_cast<std::uintptr_t>(m_.math1[i.d]));
        call(rax);
        mov(cell(i.a), rax);
        return true;
      case Op::MATH2:
        mov(rdi, cell(i.b));
        mov(rsi, cell(i.c));
        mov(rax, reinterpret_cast<std::uintptr_t>(m_.math2[i.d]));
        call(rax);
        mov(cell(i.a), rax);
        return true;
      case Op::CALL_FB: {
        bool (*const run_pou)(Vm&, std::uint32_t, Cell*) noexcept = &run;
        mov(qword[r12 + kBudget], r13);
        mov(rdi, r12);
        mov(esi, i.d);
        lea(rdx, ptr[rbx + disp(i.a)]);
        mov(rax, reinterpret_cast<std::uintptr_t>(run_pou));
        call(rax);
        mov(r13, qword[r12 + kBudget]);
        test(al, al);
        jz(exit_stop_, T_NEAR);  // the budget ran out in the callee (it left the Vm's)
        return true;
      }
      case Op::SWITCH: {
        const JumpTable& t = m_.tables[i.b];
        Label& table = switch_tables_[i.b];
        mov(rax, cell(i.a));
        mov(rdx, static_cast<std::uint64_t>(t.low));
        sub(rax, rdx);  // the selector from low, unsigned: below low is above every index
        mov(rdx, static_cast<std::uint64_t>(t.targets.size()));
        cmp(rax, rdx);
        jae(at_[t.otherwise], T_NEAR);
        lea(rcx, ptr[rip + table]);
        jmp(qword[rcx + rax * 8]);
        return true;
      }
      default: return false;
    }
  }

  // One instruction's template; false when it has none (step() runs it).
  bool insn(std::uint32_t pc, const Insn& i) {
    if (!templated(m_, i)) return false;
    Num n{};
    switch (i.op) {
      case Op::HALT:
        store_all();
        jmp(exit_ok_, T_NEAR);
        return true;
      case Op::JMP: jmp(target(i.d), T_NEAR); return true;
      case Op::JMPB:
        test(r13, r13);
        jle(slow(pc), T_NEAR);
        dec(r13);
        jmp(target(i.d), T_NEAR);
        return true;
      case Op::JZ: raw_load(rax, i.a); test(rax, rax); jz(target(i.d), T_NEAR); return true;
      case Op::JNZ: raw_load(rax, i.a); test(rax, rax); jnz(target(i.d), T_NEAR); return true;
      case Op::MOV: raw_load(rax, i.b); raw_store(i.a, rax); return true;
      case Op::AND: raw_load(rax, i.b); raw_load(rcx, i.c); and_(rax, rcx); raw_store(i.a, rax); return true;
      case Op::OR: raw_load(rax, i.b); raw_load(rcx, i.c); or_(rax, rcx); raw_store(i.a, rax); return true;
      case Op::XOR: raw_load(rax, i.b); raw_load(rcx, i.c); xor_(rax, rcx); raw_store(i.a, rax); return true;
      case Op::NOT_BOOL: raw_load(rax, i.b); xor_(rax, 1); raw_store(i.a, rax); return true;
      case Op::GETBIT:
        raw_load(rax, i.b);
        shr(rax, static_cast<int>(i.c));
        and_(eax, 1);
        raw_store(i.a, rax);
        return true;
      default: break;
    }
    constexpr int kNum = kNumCount, kInt = 8;
    if (in_family(i.op, Op::ADD_I8, kNum, &n)) return arith('+', i, n), true;
    if (in_family(i.op, Op::SUB_I8, kNum, &n)) return arith('-', i, n), true;
    if (in_family(i.op, Op::MUL_I8, kNum, &n)) return arith('*', i, n), true;
    const Rel rels[] = {Rel::Eq, Rel::Ne, Rel::Lt, Rel::Le, Rel::Gt, Rel::Ge};
    const Op sets[] = {Op::EQ_I8, Op::NE_I8, Op::LT_I8, Op::LE_I8, Op::GT_I8, Op::GE_I8};
    for (int k = 0; k < 6; ++k)
      if (in_family(i.op, sets[k], kNum, &n)) return compare_set(rels[k], i, n), true;
    const Rel jrels[] = {Rel::Lt, Rel::Le, Rel::Gt, Rel::Ge, Rel::Eq, Rel::Ne};
    const Op jumps[] = {Op::JNLT_I8, Op::JNLE_I8, Op::JNGT_I8, Op::JNGE_I8, Op::JNEQ_I8, Op::JNNE_I8};
    for (int k = 0; k < 6; ++k)
      if (in_family(i.op, jumps[k], kNum, &n)) return compare_jump(jrels[k], i, n), true;
    const Op forms[] = {Op::MULADD_I8, Op::ADDMUL_I8, Op::MULSUB_I8, Op::SUBMUL_I8};
    for (int k = 0; k < 4; ++k)
      if (in_family(i.op, forms[k], kNum, &n)) return fused(k, i, n), true;
    if (in_family(i.op, Op::FOR_INC_I8, kInt, &n)) return for_inc(pc, i, n), true;
    if (in_family(i.op, Op::LDX_I8, kInt, &n)) {
      element(pc, i, n);
      mov(rax, qword[rbx + rcx * 8 + disp(i.b)]);
      raw_store(i.a, rax);
      return true;
    }
    if (in_family(i.op, Op::STX_I8, kInt, &n)) {
      element(pc, i, n);
      raw_load(rax, i.b);
      mov(qword[rbx + rcx * 8 + disp(i.a)], rax);
      return true;
    }
    if (in_family(i.op, Op::CLAMP_I8, kNum, &n)) return clamp(i, n), true;
    if (in_family(i.op, Op::WIDEN_TO_F64_I8, kNum, &n)) {
      if (n == Num::F32) cvtss2sd(xmm0, dword[rbx + disp(i.b)]);
      else { load_int(rax, i.b, n); cvtsi2sd(xmm0, rax); }
      store_real(i.a, xmm0, Num::F64);
      return true;
    }
    for (Op first : {Op::WIDEN_TO_I16_I8, Op::WIDEN_TO_I32_I8, Op::WIDEN_TO_I64_I8})
      if (in_family(i.op, first, kNum, &n)) {  // value-preserving: extended as n, cut to the target's width
        load_int(rax, i.b, n);
        store_int(i.a, rax, first == Op::WIDEN_TO_I16_I8 ? Num::I16 : first == Op::WIDEN_TO_I32_I8 ? Num::I32 : Num::I64);
        return true;
      }
    if (in_family(i.op, Op::DIV_I8, kNum, &n)) return divide(pc, i, n, false), true;
    if (in_family(i.op, Op::MOD_I8, kNum, &n)) return divide(pc, i, n, true), true;
    return call_out(i);
  }
};

// Every operand a displacement from the frame's register: the frame must fit
// a 32-bit displacement (it always does for the checker's limits; if not,
// the POU stays interpreted).
bool fits(const CompiledPou& p) {
  return p.frame_cells < (std::uint32_t{1} << 27) && p.code.size() < (std::size_t{1} << 24);
}

struct NativeCode {
  std::unique_ptr<Emitter> code;
};

}  // namespace

void set_engine(Module& m, Engine engine) {
  for (CompiledPou& p : m.pous) {
    p.native = nullptr;
    p.native_code.reset();
  }
  if (engine != Engine::Native) return;
  for (CompiledPou& p : m.pous) {
    if (p.code.empty() || !fits(p)) continue;
    try {
      // The largest template with its rare path (which in a loop writes
      // back and reads again 18 registers) is under 500 bytes, and a CASE's
      // table (up to 4096 targets) 8 bytes a target; pages never written
      // stay unbacked.
      std::size_t bytes = p.code.size() * 512 + 4096;
      for (const Insn& i : p.code)
        if (i.op == Op::SWITCH) bytes += m.tables[i.b].targets.size() * 8 + 8;
      auto e = std::make_unique<Emitter>(m, p, bytes);
      e->emit();
      e->setProtectModeRE();  // written, now executable and no longer writable
      p.native = e->getCode<int (*)(Vm*, Cell*) noexcept>();
      auto owner = std::make_shared<NativeCode>();
      owner->code = std::move(e);
      p.native_code = std::move(owner);
    } catch (const std::exception&) {
      // No executable memory (a hardened kernel) or code over the estimate:
      // this POU stays with the interpreter, which gives the same results.
      p.native = nullptr;
      p.native_code.reset();
    }
  }
}

#else

void set_engine(Module& m, Engine) {
  for (CompiledPou& p : m.pous) {
    p.native = nullptr;
    p.native_code.reset();
  }
}

#endif

std::size_t native_register_loops(const Module& m) {
#if SYNCPLC_ST_NATIVE
  std::size_t n = 0;
  for (const CompiledPou& p : m.pous)
    if (p.native) n += register_loops(m, p, &loop_safe, 12, 6).size();
  return n;
#else
  (void)m;
  return 0;
#endif
}

std::size_t native_pous(const Module& m) {
  std::size_t n = 0;
  for (const CompiledPou& p : m.pous) n += p.native != nullptr;
  return n;
}

}  // namespace syncplc::st::vm
