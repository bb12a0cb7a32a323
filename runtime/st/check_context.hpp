// The state of one run of the type checker, shared by its three parts:
// declarations and scopes (check_decls.cpp), expressions (check_expr.cpp)
// and statements (check_stmt.cpp). Internal to runtime/st.
#pragma once

#include <map>
#include <string>
#include <unordered_set>
#include <vector>

#include "runtime/st/checker.hpp"

namespace syncplc::st {

// The result of checking an expression. An untyped literal (or a constant
// expression of them) has `lit` set: its type is then a default (DINT or
// LINT for integers, LREAL for reals) until the context settles it.
struct Val {
  enum class Lit { None, Int, Real };
  Val(const Type* t = nullptr, Lit l = Lit::None, std::optional<ConstValue> value = std::nullopt)
      : type(t), lit(l), c(value) {}
  const Type* type = nullptr;
  Lit lit = Lit::None;
  std::optional<ConstValue> c;
  bool error() const { return type->is_error(); }
};

class Checker {
 public:
  Checker(CheckedProgram& out, const std::vector<BlockSignature>& blocks);
  void run(const std::vector<const CompilationUnit*>& units);

  // ---- declarations (check_decls.cpp) ----
  const Type* resolve(const TypeSpec& spec, const std::string& name_for_new);
  const Type* resolve_spec(const TypeSpec& spec, const std::string& name_for_new);
  const Type* named_type(const std::string& name, const SourceLoc& loc);
  std::optional<std::int64_t> const_int(const Expr& e, const Type* want, const char* what);
  // block_params: a built-in block's parameters may be named here (a
  // declaration's own initializer; block_instance checked them).
  void check_init(const Initializer& init, const Type* type, bool block_params = false);
  void declare_pou_variables(PouInfo& info, const Pou& pou);
  void declare_section(PouInfo* info, const VarSection& section, VarScope scope,
                       std::vector<std::unique_ptr<Variable>>& into);

  // ---- built-in blocks (check_blocks.cpp) ----
  void add_builtin(const BlockSignature& b);
  std::vector<Pin> block_pins(const FbType& fb);  // array pins sized by fb's parameter values
  // The reference type `name` (AXIS_REF) of instances of block type `target` (MC_AXIS), made once.
  const Type* ref_type(const std::string& name, const std::string& target);
  // The type of `var`, a declared instance of built-in block `base`, with
  // the parameters its initializer gives (error type when one is wrong or
  // a parameter without a default is left out, each reported at its place).
  const Type* block_instance(const Type* base, const Initializer& init, const std::string& var, const SourceLoc& loc);
  // Reports (at loc) and returns true when t is a built-in block a parameter of which has no value.
  bool incomplete_block(const Type* t, const SourceLoc& loc, std::string_view what);

  // ---- expressions (check_expr.cpp) ----
  Val expr(const Expr& e, const Type* want = nullptr);
  // Checks that `v` (of expression e) may go where a `target` is expected:
  // settles an untyped literal, or reports "expected X, found Y".
  void coerce(const Expr& e, const Val& v, const Type* target, std::string_view where);
  Val expect(const Expr& e, const Type* target, std::string_view where);
  void settle(const Expr& e, const Type* t);
  Val call(const Expr& e, bool as_statement, const Type* want = nullptr);
  void skim(const Argument& a);
  void bind_args(const Expr& e, const std::string& callee, const std::vector<const Pin*>& params);
  const Type* common(const Type* a, const Type* b);
  const Type* unify(const Expr& e, const Expr& a, Val& x, const Expr& b, Val& y);
  void settle_default(const Expr& e, const Val& v);
  const Type* member_of(const Expr& e, const Type* base, bool writing);
  const Type* index_of(const Expr& e, const Type* base);
  const Type* bit_of(const Expr& e, const Type* base);
  Val name(const Expr& e, const Type* want);
  Val binary(const Expr& e, const Type* want);
  Val unary(const Expr& e, const Type* want);
  Val literal(const Expr& e, const Type* want);
  Val std_call(const Expr& e, const StdFunction& f, const Type* want);
  Val conversion_call(const Expr& e, const Conversion& c);
  Val user_function_call(const Expr& e, const PouInfo& f);
  void fb_call(const Expr& e, const Type* fb_type, const std::string& instance);
  // The type of a place that is written; reports what may not be written.
  const Type* target(const Expr& e);
  Val record(const Expr& e, Val v);
  ExprInfo& info(const Expr& e) { return out_.exprs[&e]; }
  std::string suggestion(std::string_view name);  // " (did you mean X?)" over the names in scope

  // ---- recursion and self-containment (check_cycles.cpp) ----
  // A call of a user FUNCTION or FB, recorded while the bodies are checked.
  struct CallEdge {
    const PouInfo* callee = nullptr;
    SourceLoc loc;
  };
  void record_call(const PouInfo* callee, const SourceLoc& loc);
  void check_cycles();

  // ---- statements (check_stmt.cpp) ----
  void body(const std::vector<Statement>& stmts);
  void statement(const Statement& s);
  void case_statement(const Statement& s);
  void for_statement(const Statement& s);
  void condition(const Expr& e, std::string_view what);

  void error(const SourceLoc& loc, std::string message) { out_.diagnostics.error(loc, std::move(message)); }
  const Type* err() const { return types_.error(); }
  const Type* elem(Elem e) const { return types_.elem(e); }

  CheckedProgram& out_;
  TypeTable& types_;
  std::map<std::string, const Type*> fb_types_;       // by name_key: user and built-in FBs
  std::map<std::string, std::vector<BlockSignature::PinSpec>> block_specs_;  // built-in blocks' pins, by block name
  std::map<std::string, const Type*> block_instances_;  // built-in block types by their parameterization's name
  std::map<std::pair<std::int64_t, const Type*>, const Type*> pin_arrays_;  // ARRAY[1..n] OF element
  std::map<std::string, PouInfo*> functions_;         // by name_key
  std::map<std::string, const Variable*> globals_;    // by name_key
  PouInfo* pou_ = nullptr;  // the POU being checked
  int loop_depth_ = 0;
  std::vector<const Variable*> for_vars_;  // control variables of the enclosing FORs
  std::vector<std::string> resolving_;     // TYPE names being resolved (cycle detection)
  int type_depth_ = 0;                      // resolve() calls open (limited to kMaxNesting through named types)
  std::map<std::string, const TypeDecl*> type_decls_;
  std::unordered_set<const Expr*> lits_;  // expressions still untyped literals (see Val)
  std::vector<const Type*> enums_;        // every enumeration type, for unqualified values  // by name_key, before resolution
  std::map<const FbType*, const PouInfo*> fb_pous_;          // each user FB type's POU
  std::map<const PouInfo*, std::vector<CallEdge>> calls_;   // by caller, in the order of the source
};

std::string type_text(const Type* t);
ConstValue wrap(ConstValue v, const Type* t);
bool fits(const ConstValue& v, Elem e);

}  // namespace syncplc::st
