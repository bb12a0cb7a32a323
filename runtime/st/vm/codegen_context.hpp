// The state of one run of the code generator, shared by its parts: POUs,
// frames and initial images (codegen_pou.cpp), places and expressions
// (codegen_expr.cpp), calls (codegen_call.cpp) and statements
// (codegen_stmt.cpp). Internal to runtime/st/vm.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "runtime/st/vm/codegen.hpp"
#include "runtime/st/vm/var_path.hpp"

namespace syncplc::st::vm {

// Operands that name a constant of the POU being compiled carry this bit
// until the constants are placed after the temporaries (CodeGen::place_constants).
inline constexpr std::uint32_t kConstTag = 0x80000000u;

// A value in the frame: the cell(s) at `at`, of type `type`.
struct Operand {
  std::uint32_t at = 0;
  const Type* type = nullptr;
};

// A place that is read or written.
struct Place {
  enum class Kind { Direct, Indirect, Indexed };
  Kind kind = Kind::Direct;
  std::uint32_t at = 0;     // Direct: the cell; Indirect: the reference cell; Indexed: the array's first cell
  std::uint32_t k = 0;      // Indirect: cells after the referenced one
  std::uint32_t index = 0;  // Indexed: the index cell
  std::uint32_t check = 0;  // Indexed: its IndexCheck
  int bit = -1;             // a bit of the place (w.3)
  const Type* type = nullptr;  // the place's type (BOOL for a bit)
  const Type* word = nullptr;  // with a bit: the type of the word
  const Variable* root = nullptr;  // the variable the place is part of
};

// The native type of an elementary type (the enumeration's and subrange's base).
Num num_of(Elem e);
std::optional<Num> num_of(const Type* t);
IecType iec_of(Elem e);
// A constant as a cell of native type n (integers wrapped, reals rounded to n).
Cell num_cell(Num n, const ConstValue& c);

struct PouState {
  enum class Stage { None, LaidOut, Done };
  Stage stage = Stage::None;
  const PouInfo* info = nullptr;
  std::map<const Variable*, std::uint32_t> at;  // each variable's cell
};

class CodeGen {
 public:
  CodeGen(const CheckedProgram& program, const BlockRegistry* blocks, StDiagnostics& diags);
  std::unique_ptr<Module> run();

  // ---- POUs, frames, images (codegen_pou.cpp) ----
  std::uint32_t pou_index(const PouInfo* info);
  void lay_out(std::uint32_t pou);
  void compile_pou(std::uint32_t pou);
  std::uint32_t cells_of(const Type* t);
  std::uint32_t fb_pou(const Type* fb_type);  // a user FB type's POU index
  // The registered block of a built-in FB type, and its generic pins' type.
  const BlockTypeInfo* builtin(const Type* fb_type, IecType* datatype = nullptr);
  // The offset of pin `pin` of a built-in block instance from its cell (builtin_layout).
  std::uint32_t builtin_pin_at(const Type* fb_type, std::string_view pin);
  void default_image(const Type* t, Cell* at, const std::string& spelt, std::uint32_t pou);
  void apply_init(const Initializer& init, const Type* t, Cell* at);
  void const_cells(const Expr& e, const Type* t, Cell* at);
  std::uint32_t var_cell(const Variable* v);  // in the POU being compiled
  void place_constants();

  // ---- code ----
  std::uint32_t emit(Op op, std::uint32_t a = 0, std::uint32_t b = 0, std::uint32_t c = 0, std::uint32_t d = 0,
                     std::uint32_t site = 0);
  std::uint32_t pc() const { return static_cast<std::uint32_t>(code().size()); }
  std::vector<Insn>& code() { return out_->pous[pou_].code; }
  const std::vector<Insn>& code() const { return out_->pous[pou_].code; }
  void patch(std::uint32_t at, std::uint32_t target) { code()[at].d = target; }
  std::uint32_t temp(std::uint32_t cells = 1);
  std::uint32_t constant(const Cell* cells, std::uint32_t n);
  std::uint32_t constant_cell(Cell c) { return constant(&c, 1); }
  std::uint32_t site(const SourceLoc& loc, const std::string& what);
  void error(const SourceLoc& loc, std::string message);

  // ---- places and expressions (codegen_expr.cpp) ----
  Place place(const Expr& e);
  Operand read(const Place& p, std::optional<std::uint32_t> into = std::nullopt);
  void write(const Place& p, Operand v, const SourceLoc& loc);
  void note_written(const Place& p);  // a VAR_EXTERNAL written (its tag belongs to the POU's task)
  std::uint32_t ref_of(const Place& p);  // a cell holding the place's address
  Operand expr(const Expr& e, std::optional<std::uint32_t> into = std::nullopt);
  Operand convert(Operand v, const Type* to, const SourceLoc& loc);
  Operand as_i64(Operand v);
  Operand binary(const Expr& e, std::optional<std::uint32_t> into);
  Operand unary(const Expr& e, std::optional<std::uint32_t> into);
  Operand constant_of(const Expr& e, const ExprInfo& i);
  // The jumps (patch their d) taken when `cond` is false / true.
  std::vector<std::uint32_t> jumps_unless(const Expr& cond);
  std::vector<std::uint32_t> jumps_if(const Expr& cond);
  // Evaluating e can be skipped with no visible difference (no call, no fault).
  bool skippable(const Expr& e) const;

  // ---- calls (codegen_call.cpp) ----
  Operand call(const Expr& e, std::optional<std::uint32_t> into);
  Operand std_call(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t> into);
  Operand string_call(const Expr& e, const ExprInfo& i, const StdFunction& f, std::optional<std::uint32_t> into);
  Operand time_call(const Expr& e, const ExprInfo& i, const StdFunction& f, std::optional<std::uint32_t> into);
  Operand conversion(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t> into);
  Operand user_function(const Expr& e, const ExprInfo& i, std::optional<std::uint32_t> into);
  void fb_call(const Expr& e);
  std::uint32_t string_op(StringCall s);
  std::uint32_t math1(Math1Fn f);
  std::uint32_t math2(Math2Fn f);
  std::uint32_t conversion_index(ConvertFn f);
  // The cells of a place's part `off` cells in, of type t.
  Place member(Place base, std::uint32_t off, const Type* t);
  // dst := v (a value of t; a string is cut to t's capacity).
  void copy_value(std::uint32_t dst, Operand v, const Type* t, const SourceLoc& loc);
  const VarSlot* slot(std::uint32_t pou, std::string_view name);

  // ---- statements (codegen_stmt.cpp) ----
  void body(const std::vector<Statement>& stmts);
  void statement(const Statement& s);
  void assign(const Statement& s);
  void if_statement(const Statement& s);
  bool clamp_statement(const Statement& s);
  const Variable* plain_variable(const Expr& e) const;
  void case_statement(const Statement& s);
  void for_statement(const Statement& s);
  void while_statement(const Statement& s);
  void repeat_statement(const Statement& s);

  const CheckedProgram& program_;
  const BlockRegistry* blocks_;
  StDiagnostics& diags_;
  std::unique_ptr<Module> out_;
  std::vector<PouState> pous_;
  std::map<const PouInfo*, std::uint32_t> pou_of_;
  std::map<std::string, std::uint32_t> sites_;
  std::map<std::string, std::uint32_t> texts_;

  // The POU being compiled.
  std::uint32_t pou_ = 0;
  const PouInfo* info_ = nullptr;
  std::uint32_t vars_end_ = 0;    // first cell after the variables
  std::uint32_t temp_top_ = 0;    // next free temporary
  std::uint32_t temp_high_ = 0;   // the most temporaries in use at once
  std::vector<Cell> constants_;   // placed after the temporaries
  std::map<std::vector<std::uint64_t>, std::uint32_t> constant_at_;
  std::vector<std::uint32_t> my_calls_, my_strings_;  // descriptors whose operands are this POU's

  // Loops: where EXIT and CONTINUE go.
  struct Loop {
    std::vector<std::uint32_t> exits;      // jumps to patch to the loop's end
    std::vector<std::uint32_t> continues;  // jumps to patch to its next iteration
  };
  std::vector<Loop> loops_;
};

// Releases the temporaries taken while it lived (one statement's, one call's).
class TempScope {
 public:
  explicit TempScope(CodeGen& g) : g_(g), top_(g.temp_top_) {}
  ~TempScope() { g_.temp_top_ = top_; }
  TempScope(const TempScope&) = delete;
  TempScope& operator=(const TempScope&) = delete;

 private:
  CodeGen& g_;
  std::uint32_t top_;
};

}  // namespace syncplc::st::vm
