// The abstract syntax tree of a Structured Text source: plain data, what the
// parser hands the type checker.
//
// Tagged nodes (a kind and the fields of all kinds) rather than a
// std::variant per node family or a class hierarchy: every node is a value
// (copyable, comparable in tests, no ownership to manage), children are held
// in std::vector (which may name a type still incomplete), and a pass walks
// the tree with one switch per family. A few unused fields per node cost
// nothing that matters at compile time. Every node has its SourceLoc. Names
// are kept as written; IEC names are compared case-insensitively later.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"

namespace syncplc::st {

// ---- Expressions ----

enum class LiteralKind { Integer, Real, Bool, Duration, Date, TimeOfDay, DateAndTime, String, WString };

struct Literal {
  LiteralKind kind = LiteralKind::Integer;
  std::string type_prefix;  // INT#5: "INT"; "" when untyped; TIME/LTIME for durations
  std::uint64_t int_value = 0;  // Integer, Bool (0/1)
  bool negative = false;        // INT#-5
  double real_value = 0;
  std::int64_t duration_ns = 0;
  std::string text;  // String/WString: the characters; Date/TimeOfDay/DateAndTime: as written
};

enum class ExprKind {
  None,       // absent (an optional part not written)
  Literal,    // literal
  Name,       // name: a variable, or an enumeration value without its type
  EnumValue,  // type_name#name (Colour#Red)
  Member,     // operands[0].name
  Index,      // operands[0][operands[1], …]
  BitAccess,  // operands[0].bit (w.3)
  Call,       // name(args): a function or an FB instance; name empty: operands[0](args) (axes[2](…))
  Unary,      // unary_op operands[0]
  Binary,     // operands[0] binary_op operands[1]
};

enum class UnaryOp { Negate, Plus, Not };
enum class BinaryOp { Power, Multiply, Divide, Mod, Add, Subtract, Less, Greater, LessEqual, GreaterEqual,
                      Equal, NotEqual, And, Xor, Or };

// The operator as ST writes it ("**", "MOD", "<>"): for dumps and messages.
inline const char* binary_op_text(BinaryOp op) {
  switch (op) {
    case BinaryOp::Power: return "**";
    case BinaryOp::Multiply: return "*";
    case BinaryOp::Divide: return "/";
    case BinaryOp::Mod: return "MOD";
    case BinaryOp::Add: return "+";
    case BinaryOp::Subtract: return "-";
    case BinaryOp::Less: return "<";
    case BinaryOp::Greater: return ">";
    case BinaryOp::LessEqual: return "<=";
    case BinaryOp::GreaterEqual: return ">=";
    case BinaryOp::Equal: return "=";
    case BinaryOp::NotEqual: return "<>";
    case BinaryOp::And: return "AND";
    case BinaryOp::Xor: return "XOR";
    case BinaryOp::Or: return "OR";
  }
  return "?";
}

struct Argument;

struct Expr {
  ExprKind kind = ExprKind::None;
  SourceLoc loc;
  std::string name;       // Name, Member, Call, EnumValue (the value)
  std::string type_name;  // EnumValue
  Literal literal;
  int bit = 0;  // BitAccess
  UnaryOp unary_op = UnaryOp::Negate;
  BinaryOp binary_op = BinaryOp::Add;
  std::vector<Expr> operands;
  std::vector<Argument> args;  // Call
};

// One argument of a call: positional (name empty), named input (name := value),
// or output (name => value, output true; NOT name => value sets negated).
struct Argument {
  SourceLoc loc;
  std::string name;
  bool output = false;
  bool negated = false;
  Expr value;  // ExprKind::None for an output left unconnected (q => )
};

// ---- Types and initial values ----

enum class TypeKind {
  Named,     // name: an elementary type or a declared one
  String,    // STRING[length] / WSTRING[length] (wide); length None: the default capacity
  Array,     // ARRAY[dims] OF element[0]
  Struct,    // STRUCT members END_STRUCT
  Enum,      // (a, b := 2, c) with an optional base type name (INT (a, b))
  Subrange,  // name (low..high)
};

struct Initializer;
struct VarDecl;
struct TypeSpec;

struct Subrange {
  SourceLoc loc;
  Expr low;
  Expr high;
};

struct Enumerator {
  SourceLoc loc;
  std::string name;
  Expr value;  // None when not given
};

struct TypeSpec {
  TypeKind kind = TypeKind::Named;
  SourceLoc loc;
  std::string name;  // Named; Enum and Subrange: the base type ("" when none)
  bool wide = false;
  Expr length;                         // String
  std::vector<Subrange> dims;          // Array; Subrange: one
  std::vector<TypeSpec> element;       // Array: one
  std::vector<VarDecl> members;        // Struct
  std::vector<Enumerator> enumerators; // Enum
};

enum class InitKind { None, Expr, Struct, Array };

struct FieldInit;
struct ArrayInitElement;

struct Initializer {
  InitKind kind = InitKind::None;
  SourceLoc loc;
  Expr expr;
  std::vector<FieldInit> fields;           // (a := 1, b := 2)
  std::vector<ArrayInitElement> elements;  // [1, 2, 3(0)]
};

struct FieldInit {
  SourceLoc loc;
  std::string name;
  Initializer value;
};

struct ArrayInitElement {
  SourceLoc loc;
  Expr repeat;        // 3 in 3(0); None when not repeated
  Initializer value;  // None in 3(): three default values
};

// ---- Declarations ----

struct VarDecl {
  SourceLoc loc;
  std::vector<std::string> names;  // a, b, c : INT
  std::vector<SourceLoc> name_locs;
  std::string address;  // AT %IX0.0: "%IX0.0"; "" when none
  TypeSpec type;
  Initializer init;
};

enum class VarSectionKind { Var, Input, Output, InOut, Temp, External, Global };

struct VarSection {
  VarSectionKind kind = VarSectionKind::Var;
  SourceLoc loc;
  bool constant = false;
  bool retain = false;
  bool non_retain = false;
  bool persistent = false;
  std::vector<VarDecl> decls;
};

// ---- Statements ----

enum class StmtKind { Empty, Assign, Call, If, Case, For, While, Repeat, Exit, Continue, Return };

struct Statement;

struct IfBranch {
  SourceLoc loc;
  Expr condition;
  std::vector<Statement> body;
};

struct CaseLabel {
  SourceLoc loc;
  Expr low;
  Expr high;  // None unless a range (low..high)
};

struct CaseBranch {
  SourceLoc loc;
  std::vector<CaseLabel> labels;
  std::vector<Statement> body;
};

struct Statement {
  StmtKind kind = StmtKind::Empty;
  SourceLoc loc;
  Expr target;  // Assign: the variable; For: the control variable (a Name)
  Expr value;   // Assign: the value; Call: the call; Case: the selector; For: the start;
                // While, Repeat: the condition
  Expr to;      // For
  Expr by;      // For: None when not given
  std::vector<IfBranch> branches;   // If: IF and each ELSIF
  std::vector<CaseBranch> cases;    // Case
  std::vector<Statement> body;      // For, While, Repeat
  std::vector<Statement> else_body; // If, Case
  bool has_else = false;
};

// ---- Program organisation units ----

enum class PouKind { Function, FunctionBlock, Program };

struct Pou {
  PouKind kind = PouKind::Program;
  SourceLoc loc;
  std::string name;
  std::vector<TypeSpec> return_type;  // Function: one
  std::string doc;  // the comment right before the POU, or else its first comment inside
  std::vector<VarSection> sections;
  std::vector<Statement> body;
};

struct TypeDecl {
  SourceLoc loc;
  std::string name;
  TypeSpec type;
  Initializer init;
};

struct CompilationUnit {
  SourceFile file;
  std::vector<TypeDecl> types;
  std::vector<VarSection> globals;  // VAR_GLOBAL sections outside any POU
  std::vector<Pou> pous;
};

}  // namespace syncplc::st
