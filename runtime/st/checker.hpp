// The type checker of Structured Text: between the parser and the code
// generator. It reads every POU and TYPE of a project's sources (one
// CompilationUnit per file) and gives a CheckedProgram: the type of every
// expression, what each name resolved to, folded constants, each POU's
// variables and the VAR_EXTERNALs the loader matches against tags. Every
// error is reported at file:line:col, all in one run: an expression in error
// gets the error type, which no further rule reports on, so one mistake
// gives one message.
//
// Results are a side table keyed by the address of the AST node rather than
// fields added to the AST: the AST stays the parser's plain value (its dump
// and tests untouched), and the checked data is in one place the code
// generator walks with the tree. The price: the CompilationUnits must
// outlive the CheckedProgram and must not move (the loader keeps them).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "runtime/st/ast.hpp"
#include "runtime/st/diagnostic.hpp"
#include "runtime/st/std_functions.hpp"
#include "runtime/st/types.hpp"

namespace syncplc::st {

struct PouInfo;

enum class VarScope { Local, Input, Output, InOut, Temp, External, Global, Return };

struct Variable {
  std::string name;
  VarScope scope = VarScope::Local;
  const Type* type = nullptr;
  bool constant = false;
  bool retain = false;      // RETAIN or PERSISTENT
  bool persistent = false;  // PERSISTENT
  std::string address;  // AT %IX0.0
  const Initializer* init = nullptr;
  const TypeSpec* spec = nullptr;  // its type as written (an alias's own initial value)
  std::optional<ConstValue> value;  // a CONSTANT's folded scalar value
  SourceLoc loc;
};

// What a name in an expression stands for.
enum class SymbolKind {
  None, Variable, Field, FbPin, EnumValue, Constant, StdFunction, Conversion, UserFunction, FbCall
};

struct ExprInfo {
  const Type* type = nullptr;
  SymbolKind symbol = SymbolKind::None;
  const Variable* variable = nullptr;  // Variable
  const Field* field = nullptr;        // Field
  const Pin* pin = nullptr;            // FbPin
  const StdFunction* std_function = nullptr;
  std::optional<Conversion> conversion;
  const PouInfo* function = nullptr;  // UserFunction
  std::optional<ConstValue> constant;  // folded: literals and constant expressions
  // A comparison: the type both operands are compared in; a standard
  // function call: its generic type T (nullptr when it has none).
  const Type* operand_type = nullptr;
};

struct PouInfo {
  const Pou* pou = nullptr;
  std::string name;
  PouKind kind = PouKind::Program;
  const Type* return_type = nullptr;  // Function
  const FbType* fb = nullptr;         // FunctionBlock
  std::vector<std::unique_ptr<Variable>> variables;  // declaration order; Return first for a FUNCTION
  std::vector<Pin> params;  // FUNCTION: its inputs, in-outs and outputs in declaration order
  const Variable* find(std::string_view name) const;
};

// A VAR_EXTERNAL for the loader to match against a tag by name and type.
struct ExternalRef {
  std::string pou;
  std::string name;
  const Type* type = nullptr;
  bool constant = false;
  SourceLoc loc;
};

// A call that gives a built-in block's link a VAR_EXTERNAL AXIS_REF by name
// (`pwr(Axis := x)` in POU `pou`, instance `pwr` of `block`, pin `Axis`): the
// axis is known at load, so the loader checks exclusive links (one MC_Power
// per axis) with it.
struct LinkClaim {
  std::string pou;
  std::string instance;
  std::string block;
  std::string pin;
  std::string external;
  SourceLoc loc;
};

struct CheckedProgram {
  std::unique_ptr<TypeTable> types = std::make_unique<TypeTable>();
  std::unordered_map<const Expr*, ExprInfo> exprs;
  std::vector<std::unique_ptr<PouInfo>> pous;
  std::vector<std::unique_ptr<Variable>> globals;  // top-level VAR_GLOBAL
  std::vector<ExternalRef> externals;
  std::vector<LinkClaim> link_claims;
  std::unordered_map<const Argument*, const Pin*> args;  // FB and user function calls: each argument's parameter
  // Standard function calls: each argument with its parameter, in the call's order.
  std::unordered_map<const Expr*, std::vector<std::pair<const Argument*, const StdParam*>>> std_args;
  std::map<std::string, const Type*> named_types;  // by name_key: TYPE declarations
  std::map<std::string, const Initializer*> type_inits;  // by name_key: a TYPE's own initial value
  StDiagnostics diagnostics;

  bool ok() const { return !diagnostics.has_errors(); }
  const ExprInfo* info(const Expr& e) const;
  const PouInfo* pou(std::string_view name) const;
};

// Checks the units together (types and POUs of one file may use those of
// another). `blocks` are the built-in function blocks ST may instance.
CheckedProgram check(const std::vector<const CompilationUnit*>& units,
                     const std::vector<BlockSignature>& blocks = {});

}  // namespace syncplc::st
