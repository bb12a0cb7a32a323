// The code generator's statements. Loops: every backward jump counts
// against the scan's loop budget (JMPB, FOR_NEXT), so a runaway loop ends
// with a fault naming its file:line. FOR evaluates its end and step once,
// before the first iteration; CASE with dense integer labels jumps through a
// table, otherwise compares label by label in the order written.
#include <algorithm>
#include <map>

#include <fmt/format.h>

#include "runtime/st/vm/codegen_context.hpp"

namespace syncplc::st::vm {

namespace {

constexpr const char* kLoopBudget = "loop stopped: the scan's loop budget is spent";

}  // namespace

void CodeGen::body(const std::vector<Statement>& stmts) {
  for (const Statement& s : stmts) statement(s);
}

void CodeGen::statement(const Statement& s) {
  out_->pous[pou_].lines.resize(pc(), 0);
  const std::uint32_t first = pc();
  switch (s.kind) {
    case StmtKind::Empty: break;
    case StmtKind::Assign: assign(s); break;
    case StmtKind::Call: {
      TempScope scope(*this);
      call(s.value, std::nullopt);
      break;
    }
    case StmtKind::If: if_statement(s); break;
    case StmtKind::Case: case_statement(s); break;
    case StmtKind::For: for_statement(s); break;
    case StmtKind::While: while_statement(s); break;
    case StmtKind::Repeat: repeat_statement(s); break;
    case StmtKind::Exit:
      if (!loops_.empty()) loops_.back().exits.push_back(emit(Op::JMP));
      break;
    case StmtKind::Continue:
      if (!loops_.empty()) loops_.back().continues.push_back(emit(Op::JMP));
      break;
    case StmtKind::Return: emit(Op::HALT); break;
  }
  // Each instruction's line: the innermost statement that emitted it.
  auto& lines = out_->pous[pou_].lines;
  lines.resize(pc(), 0);
  for (std::uint32_t k = first; k < pc(); ++k)
    if (lines[k] == 0) lines[k] = static_cast<std::uint32_t>(s.loc.line);
}

void CodeGen::assign(const Statement& s) {
  TempScope scope(*this);
  const Place p = place(s.target);
  if (!p.type || p.type->is_error()) return;
  const ExprInfo* vi = program_.info(s.value);
  const auto np = num_of(p.type), nv = vi ? num_of(vi->type) : std::nullopt;
  // The value computed straight into the variable when nothing converts it.
  if (p.kind == Place::Kind::Direct && p.bit < 0 && np && nv && *np == *nv && p.type->kind != Type::Kind::Subrange) {
    const Operand v = expr(s.value, p.at);
    if (v.at != p.at) emit(Op::MOV, p.at, v.at);
    return;
  }
  // A string function's result written straight into a variable of the
  // same capacity (no copy; no cut can happen in the copy it saves).
  const Type* vt = vi ? vi->type : nullptr;
  if (p.kind == Place::Kind::Direct && p.bit < 0 && p.type->kind == Type::Kind::String && vt &&
      vt->kind == Type::Kind::String && vt->wide == p.type->wide && vt->length == p.type->length) {
    const Operand v = expr(s.value, p.at);
    if (v.at != p.at) write(p, v, s.loc);
    return;
  }
  const Operand v = convert(expr(s.value), p.type, s.value.loc);
  write(p, v, s.loc);
}

// A variable of the POU's own frame named alone (x): not a reference
// (VAR_IN_OUT, VAR_EXTERNAL), not a subrange (its writes are checked).
const Variable* CodeGen::plain_variable(const Expr& e) const {
  if (e.kind != ExprKind::Name) return nullptr;
  const ExprInfo* i = program_.info(e);
  const Variable* v = i ? i->variable : nullptr;
  if (!v || v->scope == VarScope::InOut || v->scope == VarScope::External || v->constant) return nullptr;
  if (!v->type || v->type->kind == Type::Kind::Subrange || !num_of(v->type)) return nullptr;
  return v;
}

// The clamp every controller writes, as one instruction (CLAMP_T):
//   IF x > hi THEN x := hi; ELSIF x < lo THEN x := lo; END_IF;
// (or lo tested first), x a plain numeric variable, each bound a variable or
// a constant written the same in its test and its assignment, all of x's
// type. Anything else is an ordinary IF.
bool CodeGen::clamp_statement(const Statement& s) {
  if (s.has_else || s.branches.size() != 2) return false;
  const Variable* x = nullptr;
  const Expr* bound[2] = {nullptr, nullptr};  // [0] lower, [1] upper
  bool upper_first = false;
  for (std::size_t k = 0; k < 2; ++k) {
    const IfBranch& b = s.branches[k];
    const Expr& c = b.condition;
    if (c.kind != ExprKind::Binary || (c.binary_op != BinaryOp::Greater && c.binary_op != BinaryOp::Less)) return false;
    if (b.body.size() != 1 || b.body[0].kind != StmtKind::Assign) return false;
    const bool upper = c.binary_op == BinaryOp::Greater;
    if (bound[upper]) return false;  // both tests the same way
    if (k == 0) upper_first = upper;
    const Variable* tested = plain_variable(c.operands[0]);
    if (!tested || tested != plain_variable(b.body[0].target) || (x && tested != x)) return false;
    x = tested;
    const ExprInfo* cmp = program_.info(c);
    if (!cmp || cmp->operand_type != x->type) return false;
    const Expr& limit = c.operands[1];
    const Expr& value = b.body[0].value;
    const ExprInfo* li = program_.info(limit);
    const ExprInfo* vi = program_.info(value);
    if (!li || !vi || li->type != x->type || vi->type != x->type) return false;
    const Variable* lv = plain_variable(limit);
    if (lv) {
      if (lv != plain_variable(value)) return false;
    } else {
      const Num n = *num_of(x->type);
      if (!li->constant || !vi->constant || num_cell(n, *li->constant).raw != num_cell(n, *vi->constant).raw)
        return false;
    }
    bound[upper] = &limit;
  }
  TempScope scope(*this);
  const Operand lo = expr(*bound[0]), hi = expr(*bound[1]);
  emit(op_of(Op::CLAMP_I8, *num_of(x->type)), var_cell(x), lo.at, hi.at, upper_first ? 0 : 1);
  return true;
}

void CodeGen::if_statement(const Statement& s) {
  if (clamp_statement(s)) return;
  std::vector<std::uint32_t> ends;
  for (std::size_t k = 0; k < s.branches.size(); ++k) {
    const IfBranch& b = s.branches[k];
    const std::vector<std::uint32_t> skip = jumps_unless(b.condition);
    body(b.body);
    if (k + 1 < s.branches.size() || s.has_else) ends.push_back(emit(Op::JMP));
    for (std::uint32_t j : skip) patch(j, pc());
  }
  if (s.has_else) body(s.else_body);
  for (std::uint32_t j : ends) patch(j, pc());
}

void CodeGen::case_statement(const Statement& s) {
  TempScope scope(*this);
  const Operand sel = expr(s.value);
  const auto n = num_of(sel.type);
  if (!n) {
    error(s.value.loc, fmt::format("the code generator cannot select on {}", sel.type->name));
    return;
  }
  struct Label {
    std::size_t branch;
    Wide low, high;
  };
  std::vector<Label> labels;
  bool constant = true;
  for (std::size_t k = 0; k < s.cases.size(); ++k)
    for (const CaseLabel& l : s.cases[k].labels) {
      const ExprInfo* lo = program_.info(l.low);
      const ExprInfo* hi = l.high.kind == ExprKind::None ? lo : program_.info(l.high);
      if (!lo || !lo->constant || !hi || !hi->constant || lo->constant->is_real) {
        constant = false;
        continue;
      }
      labels.push_back({k, lo->constant->i, hi->constant->i});
    }
  std::vector<std::uint32_t> ends;
  const bool is_int = *n != Num::F32 && *n != Num::F64;
  Wide lo = 0, hi = -1, count = 0;
  for (const Label& l : labels) {
    if (count == 0 || l.low < lo) lo = l.low;
    if (count == 0 || l.high > hi) hi = l.high;
    count += l.high - l.low + 1;
  }
  const Wide span = hi - lo + 1;
  if (constant && is_int && !labels.empty() && span <= 4096 && span <= 4 * count + 16) {
    // A jump table over lo..hi; the first branch that names a value wins.
    const Operand k = as_i64(sel);
    JumpTable table;
    table.low = static_cast<std::int64_t>(lo);
    table.targets.assign(static_cast<std::size_t>(span), ~0u);
    out_->tables.push_back(table);
    const auto t = static_cast<std::uint32_t>(out_->tables.size() - 1);
    emit(Op::SWITCH, k.at, t);
    for (std::size_t b = 0; b < s.cases.size(); ++b) {
      const std::uint32_t start = pc();
      for (const Label& l : labels)
        if (l.branch == b)
          for (Wide v = l.low; v <= l.high; ++v) {
            auto& target = out_->tables[t].targets[static_cast<std::size_t>(v - lo)];
            if (target == ~0u) target = start;
          }
      body(s.cases[b].body);
      ends.push_back(emit(Op::JMP));
    }
    const std::uint32_t otherwise = pc();
    if (s.has_else) body(s.else_body);
    const std::uint32_t end = pc();
    auto& table_ref = out_->tables[t];
    table_ref.otherwise = otherwise;
    for (auto& target : table_ref.targets)
      if (target == ~0u) target = otherwise;
    for (std::uint32_t j : ends) patch(j, end);
    return;
  }
  // Label by label.
  for (std::size_t b = 0; b < s.cases.size(); ++b) {
    std::vector<std::uint32_t> to_body;
    for (const CaseLabel& l : s.cases[b].labels) {
      TempScope inner(*this);
      const Operand low = convert(expr(l.low), sel.type, l.loc);
      const std::uint32_t t = temp();
      if (l.high.kind == ExprKind::None) {
        emit(op_of(Op::EQ_I8, *n), t, sel.at, low.at);
      } else {
        const Operand high = convert(expr(l.high), sel.type, l.loc);
        const std::uint32_t u = temp();
        emit(op_of(Op::GE_I8, *n), t, sel.at, low.at);
        emit(op_of(Op::LE_I8, *n), u, sel.at, high.at);
        emit(Op::AND, t, t, u);
      }
      to_body.push_back(emit(Op::JNZ, t));
    }
    const std::uint32_t next = emit(Op::JMP);
    for (std::uint32_t j : to_body) patch(j, pc());
    body(s.cases[b].body);
    ends.push_back(emit(Op::JMP));
    patch(next, pc());
  }
  if (s.has_else) body(s.else_body);
  for (std::uint32_t j : ends) patch(j, pc());
}

void CodeGen::for_statement(const Statement& s) {
  TempScope scope(*this);
  const Place v = place(s.target);
  const auto n = num_of(v.type);
  if (v.kind != Place::Kind::Direct || v.bit >= 0 || !n || *n == Num::F32 || *n == Num::F64) {
    error(s.target.loc, "a FOR control variable must be an integer variable of the POU (not a VAR_IN_OUT, a "
                        "VAR_EXTERNAL, a field or an element)");
    return;
  }
  {
    TempScope start_scope(*this);
    write(v, convert(expr(s.value), v.type, s.value.loc), s.loc);
  }
  // End and step once, in the control variable's type.
  const std::uint32_t end = temp();
  emit(Op::MOV, end, convert(expr(s.to), v.type, s.to.loc).at);
  std::uint32_t step;
  if (s.by.kind == ExprKind::None) {
    step = constant_cell(num_cell(*n, ConstValue{false, 1, 0}));
  } else {
    step = temp();
    emit(Op::MOV, step, convert(expr(s.by), v.type, s.by.loc).at);
  }
  const std::uint32_t enter = emit(op_of(Op::FOR_ENTER_I8, *n), v.at, end, step);
  const std::uint32_t top = pc();
  loops_.emplace_back();
  body(s.body);
  // The step 1 (written or not) takes the instruction that needs no step.
  const ExprInfo* bi = s.by.kind == ExprKind::None ? nullptr : program_.info(s.by);
  const bool step_one = s.by.kind == ExprKind::None || (bi && bi->constant && !bi->constant->is_real && bi->constant->i == 1);
  const std::uint32_t next = step_one ? emit(op_of(Op::FOR_INC_I8, *n), v.at, end, 0, top, site(s.loc, kLoopBudget))
                                      : emit(op_of(Op::FOR_NEXT_I8, *n), v.at, end, step, top, site(s.loc, kLoopBudget));
  Loop loop = std::move(loops_.back());
  loops_.pop_back();
  patch(enter, pc());
  for (std::uint32_t j : loop.exits) patch(j, pc());
  for (std::uint32_t j : loop.continues) patch(j, next);
}

void CodeGen::while_statement(const Statement& s) {
  const std::uint32_t top = pc();
  const std::vector<std::uint32_t> skip = jumps_unless(s.value);
  loops_.emplace_back();
  body(s.body);
  const std::uint32_t back = emit(Op::JMPB, 0, 0, 0, top, site(s.loc, kLoopBudget));
  Loop loop = std::move(loops_.back());
  loops_.pop_back();
  for (std::uint32_t j : skip) patch(j, pc());
  for (std::uint32_t j : loop.exits) patch(j, pc());
  for (std::uint32_t j : loop.continues) patch(j, back);
}

void CodeGen::repeat_statement(const Statement& s) {
  const std::uint32_t top = pc();
  loops_.emplace_back();
  body(s.body);
  const std::uint32_t test = pc();
  const std::vector<std::uint32_t> done = jumps_if(s.value);
  emit(Op::JMPB, 0, 0, 0, top, site(s.loc, kLoopBudget));
  Loop loop = std::move(loops_.back());
  loops_.pop_back();
  for (std::uint32_t j : done) patch(j, pc());
  for (std::uint32_t j : loop.exits) patch(j, pc());
  for (std::uint32_t j : loop.continues) patch(j, test);
}

}  // namespace syncplc::st::vm
