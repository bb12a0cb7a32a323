// The compiled form of Structured Text: what the code generator makes of a
// CheckedProgram and the interpreter runs in the scan (docs/architecture.md,
// "Structured Text: the compiled form").
//
// Register code over cells: every operand of an instruction is a cell offset
// relative to the frame of the POU instance that runs it (its variables, its
// temporaries and its constants all live in that frame), so one POU's code
// serves every instance of it and an instruction reads its operands with no
// decoding. Instructions are typed when generated (ADD_F64, LT_I16), so the
// interpreter never looks at a type. Dispatch is direct threading: each
// instruction holds the address of its handler, resolved once after code
// generation (interp.cpp), and every handler ends in its own indirect jump.
//
// Everything here is plain data built at load; the scan only reads it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/iec_type.hpp"
#include "runtime/st/ast.hpp"
#include "runtime/st/types.hpp"

namespace syncplc {
class Block;
struct BlockTypeInfo;
}

namespace syncplc::st::vm {

struct Vm;

// The native representations an instruction is typed with.
#define SYNCPLC_ST_NUM_TYPES(X) X(I8) X(I16) X(I32) X(I64) X(U8) X(U16) X(U32) X(U64) X(F32) X(F64)
#define SYNCPLC_ST_INT_TYPES(X) X(I8) X(I16) X(I32) X(I64) X(U8) X(U16) X(U32) X(U64)
#define SYNCPLC_ST_SIGNED_TYPES(X) X(I8) X(I16) X(I32) X(I64) X(F32) X(F64)
#define SYNCPLC_ST_UNSIGNED_TYPES(X) X(U8) X(U16) X(U32) X(U64)
#define SYNCPLC_ST_REAL_TYPES(X) X(F32) X(F64)

enum class Num : std::uint8_t {
#define X(t) t,
  SYNCPLC_ST_NUM_TYPES(X)
#undef X
};
inline constexpr int kNumCount = 10;

// The operations. A family written OP_T exists once per type of the named
// list; the code generator picks one with op_of(Op::ADD_I8, num).
// Operands: a, b, c, d (cell offsets in the frame unless said otherwise).
#define SYNCPLC_ST_OPS(X)                                                                              \
  /* control */                                                                                       \
  X(HALT)        /* end of a POU's body: return */                                                   \
  X(JMP)         /* goto d */                                                                        \
  X(JMPB)        /* goto d, a backward jump: counts against the loop budget (site: the loop) */    \
  X(JZ)          /* if cell a == 0 goto d */                                                         \
  X(JNZ)         /* if cell a != 0 goto d */                                                         \
  X(SWITCH)      /* goto the target of a's value in jump table b (I64 selector) */                  \
  /* moves */                                                                                         \
  X(MOV)         /* a := b (one cell) */                                                             \
  X(MOVN)        /* a[0..c) := b[0..c) */                                                            \
  X(ZERO)        /* a[0..c) := 0 */                                                                  \
  X(INIT)        /* a[0..c) := the frame image of POU d from its cell b (VAR_TEMP, FUNCTION locals) */ \
  /* addresses: a reference cell holds a Cell* */                                                    \
  X(ADDR)        /* a := address of frame cell b */                                                   \
  X(REF_ADD)     /* a := ref b + c cells */                                                          \
  X(REF_INDEX)   /* a := ref b + (index cell c - low) * stride, bounds-checked: array index d */    \
  X(LDI)         /* a[0..c) := *(ref b) [0..c) */                                                    \
  X(STI)         /* *(ref a)[0..c) := b[0..c) */                                                     \
  X(LDI1)        /* a := *(ref b + c) */                                                             \
  X(STI1)        /* *(ref a + c) := b */                                                             \
  /* bits */                                                                                          \
  X(GETBIT)      /* a := (b >> c) & 1 */                                                             \
  X(SETBIT)      /* bit c of a := cell b != 0 */                                                     \
  /* calls */                                                                                         \
  X(CALL_FB)     /* run POU d on the instance at frame cell a */                                     \
  X(CALL_FB_REF) /* run POU d on the instance ref a points to */                                     \
  X(CALL_FN)     /* call FUNCTION by descriptor d (arguments in, results out) */                     \
  X(CALL_BLOCK)  /* execute the built-in block whose Block* is in cell a (pins follow it) */          \
  X(CALL_BLOCK_REF) /* the same through ref a */                                                     \
  X(LINK_BLOCK)  /* link c of the built-in block at cell a: its pin at a + b refers to d AXIS_REF      \
                    cells; each names a link target (Vm::targets), linked when it changed (site) */  \
  X(LINK_BLOCK_REF) /* the same through ref a */                                                     \
  X(CONV)        /* a := conversion d of b (a function; faults at site c when out of range) */       \
  X(DT_TO_DATE)  /* a := the day of DT b, at its midnight (floored; before DATE's range: its first day, \
                    fault at its site) */                                                              \
  X(DT_TO_TOD)   /* a := the time of day of DT b (0 <= a < 24 h) */                                  \
  X(DATEFN)      /* a := date function d (DateFn, date_fns.hpp) of the 64-bit integers from cell b   \
                    (a fault at its site for fields out of range) */                                 \
  X(MATH1)       /* a := function d (b) (REAL/LREAL library function) */                           \
  X(MATH2)       /* a := function d (b, c) */                                                        \
  X(STRFN)       /* string function: descriptor d */                                                 \
  X(RANGE)       /* a := b clamped to subrange check d (faults at its site when outside) */          \
  X(MUX)         /* a := the cell (b + 1 + k * c) for k = cell b's value (I64) in 0 .. d - 1 */      \
  X(FAULT)       /* raise the fault of site d */                                                     \
  /* logic on bit patterns (BOOL and bit strings hold their high bits zero) */                       \
  X(AND) X(OR) X(XOR)                                                                                 \
  X(NOT_BOOL) X(NOT_U8) X(NOT_U16) X(NOT_U32) X(NOT_U64)                                              \
  X(SHL_U8) X(SHL_U16) X(SHL_U32) X(SHL_U64) X(SHR_U8) X(SHR_U16) X(SHR_U32) X(SHR_U64)               \
  X(ROL_U8) X(ROL_U16) X(ROL_U32) X(ROL_U64) X(ROR_U8) X(ROR_U16) X(ROR_U32) X(ROR_U64)               \
  /* arithmetic: integers wrap in their type; division by zero gives 0 and faults at site d */       \
  SYNCPLC_ST_NUM_FAMILY(X, ADD) SYNCPLC_ST_NUM_FAMILY(X, SUB) SYNCPLC_ST_NUM_FAMILY(X, MUL)            \
  SYNCPLC_ST_NUM_FAMILY(X, DIV) SYNCPLC_ST_NUM_FAMILY(X, MOD) SYNCPLC_ST_NUM_FAMILY(X, NEG)            \
  SYNCPLC_ST_NUM_FAMILY(X, ABS) SYNCPLC_ST_NUM_FAMILY(X, MIN) SYNCPLC_ST_NUM_FAMILY(X, MAX)            \
  SYNCPLC_ST_NUM_FAMILY(X, EQ) SYNCPLC_ST_NUM_FAMILY(X, NE) SYNCPLC_ST_NUM_FAMILY(X, LT)               \
  SYNCPLC_ST_NUM_FAMILY(X, LE) SYNCPLC_ST_NUM_FAMILY(X, GT) SYNCPLC_ST_NUM_FAMILY(X, GE)               \
  /* fused compare-and-branch: if !(a op b) goto d (the loop and IF conditions) */                   \
  SYNCPLC_ST_NUM_FAMILY(X, JNLT) SYNCPLC_ST_NUM_FAMILY(X, JNLE) SYNCPLC_ST_NUM_FAMILY(X, JNGT)         \
  SYNCPLC_ST_NUM_FAMILY(X, JNGE) SYNCPLC_ST_NUM_FAMILY(X, JNEQ) SYNCPLC_ST_NUM_FAMILY(X, JNNE)         \
  /* FOR: enter (skip to d when the range is empty) and next (step, goto d while in range) */       \
  SYNCPLC_ST_INT_FAMILY(X, FOR_ENTER) SYNCPLC_ST_INT_FAMILY(X, FOR_NEXT)                              \
  /* FOR with the step 1: if a < b then a := a + 1, goto d (counted against the loop budget) */    \
  SYNCPLC_ST_INT_FAMILY(X, FOR_INC)                                                                   \
  /* one cell of a local one-dimensional array by a checked index, typed by the index cell's type:  \
     LDX a := frame[b + (index cell c - low)], STX frame[a + (index cell c - low)] := b; array       \
     index d (out of bounds: LDX gives 0, STX writes nothing, both fault at its site) */            \
  SYNCPLC_ST_INT_FAMILY(X, LDX) SYNCPLC_ST_INT_FAMILY(X, STX)                                         \
  /* fused multiply and add, rounded after each as the two operations are (no FMA):                \
     MULADD a := b * c + d, ADDMUL a := d + b * c, MULSUB a := b * c - d, SUBMUL a := d - b * c      \
     (the operands in the order written) */                                                          \
  SYNCPLC_ST_NUM_FAMILY(X, MULADD) SYNCPLC_ST_NUM_FAMILY(X, ADDMUL)                                   \
  SYNCPLC_ST_NUM_FAMILY(X, MULSUB) SYNCPLC_ST_NUM_FAMILY(X, SUBMUL)                                   \
  /* a := b converted between native types, value-preserving (the implicit widenings) */            \
  SYNCPLC_ST_NUM_FAMILY(X, WIDEN_TO_I16) SYNCPLC_ST_NUM_FAMILY(X, WIDEN_TO_I32)                       \
  SYNCPLC_ST_NUM_FAMILY(X, WIDEN_TO_I64) SYNCPLC_ST_NUM_FAMILY(X, WIDEN_TO_F32)                       \
  SYNCPLC_ST_NUM_FAMILY(X, WIDEN_TO_F64)                                                              \
  /* the clamping IF (codegen_stmt.cpp, clamp_statement): d = 0: IF a > c THEN a := c ELSIF a < b   \
     THEN a := b; d = 1: the lower bound tested first */                                             \
  SYNCPLC_ST_NUM_FAMILY(X, CLAMP)

#define SYNCPLC_ST_NUM_FAMILY(X, op) \
  X(op##_I8) X(op##_I16) X(op##_I32) X(op##_I64) X(op##_U8) X(op##_U16) X(op##_U32) X(op##_U64) X(op##_F32) X(op##_F64)
#define SYNCPLC_ST_INT_FAMILY(X, op) \
  X(op##_I8) X(op##_I16) X(op##_I32) X(op##_I64) X(op##_U8) X(op##_U16) X(op##_U32) X(op##_U64)

enum class Op : std::uint16_t {
#define X(op) op,
  SYNCPLC_ST_OPS(X)
#undef X
  COUNT
};

std::string_view op_name(Op op);
// The operations whose d is a cell operand too (the others' d is a target,
// a descriptor's index or a count).
inline bool d_is_cell(Op op) { return op >= Op::MULADD_I8 && op <= Op::SUBMUL_F64; }
// The member of the typed family starting at `first` (ADD_I8) for `n`.
inline Op op_of(Op first, Num n) { return static_cast<Op>(static_cast<int>(first) + static_cast<int>(n)); }

struct Insn {
  const void* handler = nullptr;  // direct threading: set by finalize()
  Op op = Op::HALT;
  std::uint32_t a = 0, b = 0, c = 0, d = 0;
  std::uint32_t site = 0;  // FaultSite of an instruction that may fault or loop
};

// Where a runtime fault happened, as the text its event carries: static for
// the process (interned, see fault_text), so an event never owns memory.
struct FaultSite {
  const char* message = "";  // "division by zero at conveyor.st:12:7"
};

// One array dimension as an index instruction checks it.
struct IndexCheck {
  std::int64_t low = 0;
  std::uint64_t count = 0;
  std::uint32_t stride = 1;  // cells per element
  Num index = Num::I64;      // the index cell's type
  std::uint32_t site = 0;    // FaultSite when out of bounds
};

struct RangeCheck {
  Num num = Num::I64;
  std::int64_t low = 0, high = 0;
  std::uint32_t site = 0;
};

struct JumpTable {
  std::int64_t low = 0;
  std::vector<std::uint32_t> targets;  // pc of each selector value from low
  std::uint32_t otherwise = 0;
};

// Cells copied into or out of a FUNCTION's frame at a call.
struct CellCopy {
  std::uint32_t from = 0, to = 0, count = 1;
};

struct FunctionCall {
  std::uint32_t pou = 0;
  std::vector<CellCopy> in;   // caller frame -> callee frame
  std::vector<CellCopy> out;  // callee frame -> caller frame (result and outputs)
};

using ConvertFn = Cell (*)(Cell in, bool* out_of_range) noexcept;  // as iec_convert.hpp's
using Math1Fn = Cell (*)(Cell in) noexcept;
using Math2Fn = Cell (*)(Cell a, Cell b) noexcept;

// A string operation (strings_op.cpp over st_string.hpp). Operands are
// frame cells: strings, L and P widened to LINT, a value to convert.
enum class StringFn : std::uint8_t {
  Assign,    // dst := a0
  Literal,   // dst := the text of literal `text` (Module::texts)
  Concat, Left, Right, Mid, Insert, Delete, Replace,
  Len, Find,                 // dst (INT) := LEN(a0) / FIND(a0, a1)
  Eq, Ne, Lt, Le, Gt, Ge,    // dst (BOOL) := a0 op a1
  ToString,                  // dst := the text of a0, a value of `type`
  FromString,                // dst (a value of `type`) := a0 parsed
};

struct StringCall {
  StringFn fn = StringFn::Assign;
  bool wide = false;
  IecType type = IecType::LREAL;  // ToString, FromString
  std::uint32_t dst = 0;
  std::int32_t capacity = 0;  // the destination's (strings)
  std::uint32_t args[4] = {};
  std::uint32_t text = 0;     // Literal
  std::uint32_t site = 0;     // FaultSite when truncated or given a bad argument
};

// A variable of a POU in its frame. `type` points into the CheckedProgram
// the module was compiled from (the loader keeps both).
struct VarSlot {
  std::string name;
  int scope = 0;  // st::VarScope
  const Type* type = nullptr;
  std::uint32_t at = 0, cells = 1;
  bool retain = false;
  bool persistent = false;
  bool constant = false;  // VAR CONSTANT: the code uses its declared value
};

// One compiled POU: its code and the layout of its frame.
struct CompiledPou {
  std::string name;
  PouKind kind = PouKind::Program;
  std::vector<VarSlot> vars;  // declaration order
  std::vector<Insn> code;
  std::uint32_t frame_cells = 0;  // variables, temporaries, constants
  std::vector<Cell> image;        // the frame's initial contents (also every constant)
  std::uint32_t temp_begin = 0, temp_cells = 0;  // VAR_TEMP: reset from image at each call
  std::uint32_t fn_frame = 0;  // FUNCTION: its static frame's offset in a root's area
  std::vector<std::uint32_t> lines;  // source line of each instruction (for faults and tests)
  std::vector<std::string> externals_written;  // VAR_EXTERNALs the body writes (or passes as VAR_IN_OUT)
  // The same code as machine code (native_x64.cpp), when the module's engine
  // is native: run() calls it in place of the interpreter. 1: ran to its end,
  // 0: the loop budget ran out (as run()'s result).
  int (*native)(Vm* vm, Cell* frame) noexcept = nullptr;
  std::shared_ptr<const void> native_code;  // owns the executable memory
};

// A built-in block embedded in a frame: created for every instance at
// instantiation with the parameters of its FB type, its Block* stored in
// cell `at` and pin k's cells from at + pin_at[k] (builtin_layout,
// var_path.hpp: in declaration order, an array pin one cell per element).
struct BlockSlot {
  const BlockTypeInfo* type = nullptr;
  std::uint32_t at = 0;
  const FbType* fb = nullptr;  // the checker's type: parameter values, pin types
  std::vector<std::uint32_t> pin_at;
  IecType datatype = IecType::LREAL;  // a generic block's type (CTU_DINT: DINT; CTU: its default, INT)
};

// Everything compiled from a project's sources.
struct Module {
  std::vector<CompiledPou> pous;
  std::vector<FaultSite> sites;
  std::vector<IndexCheck> indexes;
  std::vector<RangeCheck> ranges;
  std::vector<JumpTable> tables;
  std::vector<FunctionCall> calls;
  std::vector<ConvertFn> conversions;
  std::vector<Math1Fn> math1;
  std::vector<Math2Fn> math2;
  std::vector<StringCall> strings;
  std::vector<std::string> texts;  // string literals (UTF-8)
  // Per POU, the built-in blocks of its frame (nested FB instances' own
  // slots are in their POU's list, at offsets relative to their frame).
  std::vector<std::vector<BlockSlot>> block_slots;
  // Per POU, the FB instances embedded in its frame: (offset, POU index), for
  // instantiation to reach nested built-in blocks.
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> nested;
  std::uint32_t function_area = 0;  // cells of all FUNCTIONs' static frames
  std::uint32_t scratch_cells = 1;  // the largest element an index may redirect to scratch
  int find(std::string_view pou) const;  // -1 when none
};

// The text of a fault event at a site: interned for the life of the process
// (events carry static text; the same site across online changes reuses it).
const char* fault_text(const std::string& text);

}  // namespace syncplc::st::vm
