// The interpreter: one handler per instruction, direct-threaded (each
// instruction holds its handler's address; every handler ends with its own
// indirect jump, so the branch predictor learns each handler's successors).
// GCC's labels as values; the file is built with -Wpedantic off for that.
//
// Integer arithmetic wraps in the operand's type (computed in the unsigned
// type of its width: no signed overflow, no UB). Division and MOD by zero
// give 0 and a fault; the most negative value divided by -1 wraps to itself.
// Reals follow IEC 60559 (a REAL is computed in float, not in double).
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "runtime/core/finite_guard.hpp"
#include "runtime/st/vm/date_fns.hpp"
#include "runtime/st/vm/strings_op.hpp"
#include "runtime/st/vm/vm.hpp"

#pragma GCC diagnostic ignored "-Wpedantic"

namespace syncplc::st::vm {

namespace {

using I8 = std::int8_t;
using I16 = std::int16_t;
using I32 = std::int32_t;
using I64 = std::int64_t;
using U8 = std::uint8_t;
using U16 = std::uint16_t;
using U32 = std::uint32_t;
using U64 = std::uint64_t;
using F32 = float;
using F64 = double;

template <class T>
inline T rd(const Cell& c) noexcept { return c.get<T>(); }
template <class T>
inline void wr(Cell& c, T v) noexcept { c.set<T>(v); }

inline Cell* ptr(const Cell& c) noexcept { return reinterpret_cast<Cell*>(static_cast<std::uintptr_t>(c.raw)); }
inline void set_ptr(Cell& c, const void* p) noexcept { c.raw = reinterpret_cast<std::uintptr_t>(p); }

// Wrapping arithmetic in T's width: through the unsigned type (promoted
// types are cast back, which is modulo 2^N since C++20).
template <class T>
using Wu = std::conditional_t<(sizeof(T) < 4), std::uint32_t, std::make_unsigned_t<T>>;

template <class T>
inline T add(T a, T b) noexcept {
  if constexpr (std::is_floating_point_v<T>) return a + b;
  else return static_cast<T>(static_cast<Wu<T>>(static_cast<Wu<T>>(a) + static_cast<Wu<T>>(b)));
}
template <class T>
inline T sub(T a, T b) noexcept {
  if constexpr (std::is_floating_point_v<T>) return a - b;
  else return static_cast<T>(static_cast<Wu<T>>(static_cast<Wu<T>>(a) - static_cast<Wu<T>>(b)));
}
template <class T>
inline T mul(T a, T b) noexcept {
  if constexpr (std::is_floating_point_v<T>) return a * b;
  else return static_cast<T>(static_cast<Wu<T>>(static_cast<Wu<T>>(a) * static_cast<Wu<T>>(b)));
}
template <class T>
inline T neg(T a) noexcept {
  if constexpr (std::is_floating_point_v<T>) return -a;
  else return static_cast<T>(static_cast<Wu<T>>(Wu<T>{0} - static_cast<Wu<T>>(a)));
}
template <class T>
inline T abs_of(T a) noexcept {
  if constexpr (std::is_floating_point_v<T>) return std::fabs(a);
  else if constexpr (std::is_signed_v<T>) return a < 0 ? neg(a) : a;
  else return a;
}
// Division: false when by zero (the caller faults; the result is 0).
template <class T>
inline bool div(T a, T b, T* r) noexcept {
  if constexpr (std::is_floating_point_v<T>) {
    *r = a / b;
    return true;
  } else {
    if (b == 0) { *r = 0; return false; }
    if constexpr (std::is_signed_v<T>)
      if (b == -1) { *r = neg(a); return true; }
    *r = static_cast<T>(a / b);
    return true;
  }
}
// MOD: the sign of the dividend (IEC: A MOD B = A - (A / B) * B, truncating).
template <class T>
inline bool mod(T a, T b, T* r) noexcept {
  if constexpr (std::is_floating_point_v<T>) {
    *r = std::fmod(a, b);
    return true;
  } else {
    if (b == 0) { *r = 0; return false; }
    if constexpr (std::is_signed_v<T>)
      if (b == -1) { *r = 0; return true; }
    *r = static_cast<T>(a % b);
    return true;
  }
}

template <class T>
inline T index_value(const Cell& c) noexcept { return rd<T>(c); }

// An index cell's value as a signed 64-bit number, saturated (a ULINT index
// above INT64_MAX is out of every array's bounds anyway).
inline std::int64_t read_index(const Cell& c, Num n) noexcept {
  switch (n) {
    case Num::I8: return rd<I8>(c);
    case Num::I16: return rd<I16>(c);
    case Num::I32: return rd<I32>(c);
    case Num::I64: return rd<I64>(c);
    case Num::U8: return rd<U8>(c);
    case Num::U16: return rd<U16>(c);
    case Num::U32: return rd<U32>(c);
    case Num::U64: {
      const U64 v = rd<U64>(c);
      return v > static_cast<U64>(std::numeric_limits<I64>::max()) ? std::numeric_limits<I64>::max()
                                                                   : static_cast<I64>(v);
    }
    default: return 0;
  }
}

// Element offset of a checked index, or -1 when out of bounds.
inline std::int64_t element(const IndexCheck& k, const Cell& index) noexcept {
  const std::int64_t v = read_index(index, k.index);
  const std::uint64_t at = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(k.low);
  if (at >= k.count) return -1;
  return static_cast<std::int64_t>(at * k.stride);
}

// For a step of any type (an unsigned one is never negative; no
// -Wtype-limits for it).
template <class T>
inline bool is_negative(T v) noexcept {
  if constexpr (std::is_signed_v<T>) return v < T{0};
  else return false;
}

// An index cell of type T as a signed 64-bit number, saturated as read_index.
template <class T>
inline std::int64_t index_as_i64(const Cell& c) noexcept {
  if constexpr (std::is_same_v<T, U64>) {
    const U64 v = rd<U64>(c);
    return v > static_cast<U64>(std::numeric_limits<I64>::max()) ? std::numeric_limits<I64>::max() : static_cast<I64>(v);
  } else {
    return static_cast<I64>(rd<T>(c));
  }
}

// A product as the separate MUL rounds it: kept out of a contraction into a
// fused multiply-add (-ffp-contract=fast with an FMA target), so MULADD gives
// the bits MUL then ADD give.
template <class T>
inline T rounded(T v) noexcept {
  if constexpr (std::is_floating_point_v<T>) {
#if defined(__x86_64__) || defined(__i386__)
    asm("" : "+x"(v));
#elif defined(__aarch64__)
    asm("" : "+w"(v));
#else
    volatile T keep = v;
    v = keep;
#endif
  }
  return v;
}

template <class T>
inline void range_store(Vm& vm, Cell& dst, const Cell& src, const RangeCheck& r) noexcept {
  const std::int64_t v = static_cast<std::int64_t>(rd<T>(src));
  if (v < r.low) {
    wr<T>(dst, static_cast<T>(r.low));
    vm.fault(r.site, static_cast<double>(v));
  } else if (v > r.high) {
    wr<T>(dst, static_cast<T>(r.high));
    vm.fault(r.site, static_cast<double>(v));
  } else {
    dst = src;
  }
}

template <class U>
inline U shl(U v, std::int64_t n) noexcept {
  constexpr int w = sizeof(U) * 8;
  return n < 0 || n >= w ? U{0} : static_cast<U>(static_cast<U64>(v) << n);
}
template <class U>
inline U shr(U v, std::int64_t n) noexcept {
  constexpr int w = sizeof(U) * 8;
  return n < 0 || n >= w ? U{0} : static_cast<U>(static_cast<U64>(v) >> n);
}
template <class U>
inline U rol(U v, std::int64_t n) noexcept {
  constexpr int w = sizeof(U) * 8;
  const int k = static_cast<int>(static_cast<U64>(n) & (w - 1));
  if (k == 0) return v;
  return static_cast<U>((static_cast<U64>(v) << k) | (static_cast<U64>(v) >> (w - k)));
}
template <class U>
inline U ror(U v, std::int64_t n) noexcept {
  constexpr int w = sizeof(U) * 8;
  const int k = static_cast<int>(static_cast<U64>(n) & (w - 1));
  if (k == 0) return v;
  return static_cast<U>((static_cast<U64>(v) >> k) | (static_cast<U64>(v) << (w - k)));
}

// Whether a reference points into the scratch area, where an index out of
// bounds sends its element.
inline bool in_scratch(const Vm& vm, const Cell* p) noexcept {
  const auto at = reinterpret_cast<std::uintptr_t>(p), from = reinterpret_cast<std::uintptr_t>(vm.scratch);
  return at >= from && at < from + vm.module->scratch_cells * sizeof(Cell);
}

// Links `link` of the built-in block at `base` to the targets its AXIS_REF
// pin (at base + pin: a reference, then per element the Block* last linked)
// names. Only a changed target calls Block::link: a compare per scan. An
// AXIS_REF naming no target (a variable never given an axis) faults at
// `site`; the block keeps the target it had.
inline void link_block(Vm& vm, Cell* base, std::uint32_t pin, std::uint32_t link, std::uint32_t n,
                       std::uint32_t site) noexcept {
  Block* b = reinterpret_cast<Block*>(static_cast<std::uintptr_t>(base[0].raw));
  const Cell* refs = ptr(base[pin]);
  Cell* linked = base + pin + 1;
  for (std::uint32_t e = 0; e < n; ++e) {
    const std::uint64_t k = refs[e].raw;
    if (k == 0 || k > vm.target_count) {
      vm.fault(site, static_cast<double>(e + 1));
      continue;
    }
    Block* target = vm.targets[k - 1];
    if (!target) {  // not linked by the owner (a VM without a project)
      vm.fault(site, static_cast<double>(e + 1));
      continue;
    }
    if (linked[e].raw == reinterpret_cast<std::uintptr_t>(target)) continue;
    linked[e].raw = reinterpret_cast<std::uintptr_t>(target);
    b->link(static_cast<int>(link), e, *target);
  }
}

// The one function with the labels: run() with frame == nullptr hands out the
// label table instead of running (how finalize() learns the addresses).
//
// Step = true makes the other instance of it: one instruction, *at, is run
// and *step_at is left at the next one (nullptr after HALT). Native code
// (native_x64.cpp) calls it for every instruction it has no template of, so
// each instruction's meaning is written once, here.
template <bool Step>
const void* const* exec(Vm& vm, const CompiledPou* pou, Cell* f, bool* ok, const Insn** step_at) noexcept {
  static const void* const labels[] = {
#define X(op) &&L_##op,
      SYNCPLC_ST_OPS(X)
#undef X
  };
  if (!f) return labels;
  const Module& m = *vm.module;
  const Insn* const code = pou->code.data();
  const Insn* ip = Step ? *step_at : code;
  // The loop budget in a local: vm.budget is an int64 in memory that every
  // store to a cell may alias, so counting there costs a load and a store on
  // each backward jump. Written back before a call (the callee counts on)
  // and on every way out.
  std::int64_t budget = vm.budget;
#define DISPATCH()                \
  do {                            \
    if constexpr (Step) {         \
      vm.budget = budget;         \
      *step_at = ip;              \
      return nullptr;             \
    } else {                      \
      goto *ip->handler;          \
    }                             \
  } while (0)
#define NEXT() \
  do {         \
    ++ip;      \
    DISPATCH(); \
  } while (0)
#define JUMP(target)        \
  do {                      \
    ip = code + (target);   \
    DISPATCH();             \
  } while (0)
  if constexpr (Step) goto *labels[static_cast<int>(ip->op)];
  else goto *ip->handler;

L_HALT:
  vm.budget = budget;
  *ok = true;
  if constexpr (Step) *step_at = nullptr;
  return nullptr;
L_JMP:
  JUMP(ip->d);
  // A backward jump: one of the scan's loop budget; when it is spent the
  // whole call chain stops at this loop (its site names it).
#define COUNT_BACKWARD_JUMP()                   \
  do {                                          \
    if (--budget < 0) {                         \
      vm.budget = budget;                       \
      vm.stopped = m.sites[ip->site].message;   \
      *ok = false;                              \
      return nullptr;                           \
    }                                           \
  } while (0)
L_JMPB:
  COUNT_BACKWARD_JUMP();
  JUMP(ip->d);
L_JZ:
  if (f[ip->a].raw == 0) JUMP(ip->d);
  NEXT();
L_JNZ:
  if (f[ip->a].raw != 0) JUMP(ip->d);
  NEXT();
L_SWITCH: {
  const JumpTable& t = m.tables[ip->b];
  const std::uint64_t k = static_cast<std::uint64_t>(rd<I64>(f[ip->a])) - static_cast<std::uint64_t>(t.low);
  JUMP(k < t.targets.size() ? t.targets[k] : t.otherwise);
}
L_MOV:
  f[ip->a] = f[ip->b];
  NEXT();
L_MOVN:
  std::memmove(f + ip->a, f + ip->b, ip->c * sizeof(Cell));
  NEXT();
L_ZERO:
  std::memset(static_cast<void*>(f + ip->a), 0, ip->c * sizeof(Cell));
  NEXT();
L_INIT:
  std::memcpy(f + ip->a, m.pous[ip->d].image.data() + ip->b, ip->c * sizeof(Cell));
  NEXT();
L_ADDR:
  set_ptr(f[ip->a], f + ip->b);
  NEXT();
L_REF_ADD:
  set_ptr(f[ip->a], ptr(f[ip->b]) + ip->c);
  NEXT();
L_REF_INDEX: {
  const IndexCheck& k = m.indexes[ip->d];
  const std::int64_t at = element(k, f[ip->c]);
  if (at < 0) {
    vm.fault(k.site, static_cast<double>(read_index(f[ip->c], k.index)));
    std::memset(static_cast<void*>(vm.scratch), 0, k.stride * sizeof(Cell));
    set_ptr(f[ip->a], vm.scratch);
  } else {
    set_ptr(f[ip->a], ptr(f[ip->b]) + at);
  }
  NEXT();
}
L_LDI:
  std::memmove(f + ip->a, ptr(f[ip->b]), ip->c * sizeof(Cell));
  NEXT();
L_STI:
  std::memmove(ptr(f[ip->a]), f + ip->b, ip->c * sizeof(Cell));
  NEXT();
L_LDI1:
  f[ip->a] = ptr(f[ip->b])[ip->c];
  NEXT();
L_STI1:
  ptr(f[ip->a])[ip->c] = f[ip->b];
  NEXT();
L_GETBIT:
  wr<bool>(f[ip->a], ((f[ip->b].raw >> ip->c) & 1u) != 0);
  NEXT();
L_SETBIT:
  if (f[ip->b].raw != 0) f[ip->a].raw |= std::uint64_t{1} << ip->c;
  else f[ip->a].raw &= ~(std::uint64_t{1} << ip->c);
  NEXT();
L_CALL_FB:
  vm.budget = budget;
  if (!run(vm, ip->d, f + ip->a)) {
    *ok = false;
    return nullptr;
  }
  budget = vm.budget;
  NEXT();
L_CALL_FB_REF:
  // An element out of bounds (its index faulted) is the scratch area: no
  // instance is there (a built-in block's pointer in it is null), so the
  // call does nothing.
  if (in_scratch(vm, ptr(f[ip->a]))) NEXT();
  vm.budget = budget;
  if (!run(vm, ip->d, ptr(f[ip->a]))) {
    *ok = false;
    return nullptr;
  }
  budget = vm.budget;
  NEXT();
L_CALL_FN: {
  const FunctionCall& call = m.calls[ip->d];
  const CompiledPou& callee = m.pous[call.pou];
  Cell* cf = vm.functions + callee.fn_frame;
  std::memcpy(cf, callee.image.data(), callee.frame_cells * sizeof(Cell));
  for (const CellCopy& c : call.in) std::memcpy(cf + c.to, f + c.from, c.count * sizeof(Cell));
  vm.budget = budget;
  if (!run(vm, call.pou, cf)) {
    *ok = false;
    return nullptr;
  }
  budget = vm.budget;
  for (const CellCopy& c : call.out) std::memcpy(f + c.to, cf + c.from, c.count * sizeof(Cell));
  NEXT();
}
L_CALL_BLOCK: {
  Block* b = reinterpret_cast<Block*>(static_cast<std::uintptr_t>(f[ip->a].raw));
  execute_guarded(*b, *vm.ctx);
  if (ip->c) end_of_scan_guarded(*b, *vm.ctx);  // a unit delay: its sample is taken at the call
  NEXT();
}
L_CALL_BLOCK_REF: {
  if (in_scratch(vm, ptr(f[ip->a]))) NEXT();  // as CALL_FB_REF
  Block* b = reinterpret_cast<Block*>(static_cast<std::uintptr_t>(ptr(f[ip->a])->raw));
  execute_guarded(*b, *vm.ctx);
  if (ip->c) end_of_scan_guarded(*b, *vm.ctx);
  NEXT();
}
L_LINK_BLOCK:
  link_block(vm, f + ip->a, ip->b, ip->c, ip->d, ip->site);
  NEXT();
L_LINK_BLOCK_REF:
  if (in_scratch(vm, ptr(f[ip->a]))) NEXT();  // as CALL_BLOCK_REF
  link_block(vm, ptr(f[ip->a]), ip->b, ip->c, ip->d, ip->site);
  NEXT();
L_CONV: {
  bool out_of_range = false;
  f[ip->a] = m.conversions[ip->d](f[ip->b], &out_of_range);
  if (out_of_range) vm.fault(ip->site);
  NEXT();
}
  // A DT is nanoseconds since 1970-01-01 00:00 (UTC); its day is the
  // floored quotient by a day's nanoseconds.
L_DT_TO_DATE: {
  constexpr std::int64_t kDay = 86'400'000'000'000;
  const std::int64_t dt = rd<std::int64_t>(f[ip->b]);
  std::int64_t day = dt / kDay - (dt % kDay < 0 ? 1 : 0);
  // DT's first day (1677-09-21) began before INT64_MIN ns: it has no DATE.
  constexpr std::int64_t kFirstDay = std::numeric_limits<std::int64_t>::min() / kDay;
  if (day < kFirstDay) {
    day = kFirstDay;
    vm.fault(ip->site, static_cast<double>(dt));
  }
  wr<std::int64_t>(f[ip->a], day * kDay);
  NEXT();
}
L_DT_TO_TOD: {
  constexpr std::int64_t kDay = 86'400'000'000'000;
  const std::int64_t dt = rd<std::int64_t>(f[ip->b]);
  const std::int64_t r = dt % kDay;
  wr<std::int64_t>(f[ip->a], r < 0 ? r + kDay : r);
  NEXT();
}
L_DATEFN: {
  bool fault = false;
  f[ip->a] = date_fn(static_cast<DateFn>(ip->d), f + ip->b, &fault);
  if (fault) vm.fault(ip->site);
  NEXT();
}
L_MATH1:
  f[ip->a] = m.math1[ip->d](f[ip->b]);
  NEXT();
L_MATH2:
  f[ip->a] = m.math2[ip->d](f[ip->b], f[ip->c]);
  NEXT();
L_STRFN:
  string_op(vm, f, m.strings[ip->d]);
  NEXT();
L_RANGE: {
  const RangeCheck& r = m.ranges[ip->d];
  switch (r.num) {
    case Num::I8: range_store<I8>(vm, f[ip->a], f[ip->b], r); break;
    case Num::I16: range_store<I16>(vm, f[ip->a], f[ip->b], r); break;
    case Num::I32: range_store<I32>(vm, f[ip->a], f[ip->b], r); break;
    case Num::U8: range_store<U8>(vm, f[ip->a], f[ip->b], r); break;
    case Num::U16: range_store<U16>(vm, f[ip->a], f[ip->b], r); break;
    case Num::U32: range_store<U32>(vm, f[ip->a], f[ip->b], r); break;
    case Num::U64: range_store<U64>(vm, f[ip->a], f[ip->b], r); break;
    default: range_store<I64>(vm, f[ip->a], f[ip->b], r); break;
  }
  NEXT();
}
L_MUX: {
  std::int64_t k = rd<I64>(f[ip->b]);
  if (k < 0 || k >= static_cast<std::int64_t>(ip->d)) {
    vm.fault(ip->site, static_cast<double>(k));
    k = k < 0 ? 0 : static_cast<std::int64_t>(ip->d) - 1;  // the nearest input
  }
  std::memmove(f + ip->a, f + ip->b + 1 + k * ip->c, ip->c * sizeof(Cell));
  NEXT();
}
L_FAULT:
  vm.fault(ip->site);
  NEXT();
L_AND:
  f[ip->a].raw = f[ip->b].raw & f[ip->c].raw;
  NEXT();
L_OR:
  f[ip->a].raw = f[ip->b].raw | f[ip->c].raw;
  NEXT();
L_XOR:
  f[ip->a].raw = f[ip->b].raw ^ f[ip->c].raw;
  NEXT();
L_NOT_BOOL:
  f[ip->a].raw = f[ip->b].raw ^ 1u;
  NEXT();
L_NOT_U8:
  f[ip->a].raw = f[ip->b].raw ^ 0xFFu;
  NEXT();
L_NOT_U16:
  f[ip->a].raw = f[ip->b].raw ^ 0xFFFFu;
  NEXT();
L_NOT_U32:
  f[ip->a].raw = f[ip->b].raw ^ 0xFFFFFFFFu;
  NEXT();
L_NOT_U64:
  f[ip->a].raw = ~f[ip->b].raw;
  NEXT();

#define SHIFT(name, fn, U)                            \
  L_##name:                                           \
  wr<U>(f[ip->a], fn<U>(rd<U>(f[ip->b]), rd<I64>(f[ip->c]))); \
  NEXT();
  SHIFT(SHL_U8, shl, U8) SHIFT(SHL_U16, shl, U16) SHIFT(SHL_U32, shl, U32) SHIFT(SHL_U64, shl, U64)
  SHIFT(SHR_U8, shr, U8) SHIFT(SHR_U16, shr, U16) SHIFT(SHR_U32, shr, U32) SHIFT(SHR_U64, shr, U64)
  SHIFT(ROL_U8, rol, U8) SHIFT(ROL_U16, rol, U16) SHIFT(ROL_U32, rol, U32) SHIFT(ROL_U64, rol, U64)
  SHIFT(ROR_U8, ror, U8) SHIFT(ROR_U16, ror, U16) SHIFT(ROR_U32, ror, U32) SHIFT(ROR_U64, ror, U64)
#undef SHIFT

#define BIN(op, T, expr)                    \
  L_##op##_##T: {                           \
    const T x = rd<T>(f[ip->b]);            \
    const T y = rd<T>(f[ip->c]);            \
    wr<T>(f[ip->a], expr);                  \
    NEXT();                                 \
  }
#define ARITH(T)                                 \
  BIN(ADD, T, add<T>(x, y))                      \
  BIN(SUB, T, sub<T>(x, y))                      \
  BIN(MUL, T, mul<T>(x, y))                      \
  BIN(MIN, T, (y < x ? y : x))                   \
  BIN(MAX, T, (x < y ? y : x))                   \
  L_DIV_##T: {                                   \
    T r;                                         \
    if (!div<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c]), &r)) vm.fault(ip->site); \
    wr<T>(f[ip->a], r);                          \
    NEXT();                                      \
  }                                              \
  L_MOD_##T: {                                   \
    T r;                                         \
    if (!mod<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c]), &r)) vm.fault(ip->site); \
    wr<T>(f[ip->a], r);                          \
    NEXT();                                      \
  }                                              \
  L_NEG_##T:                                     \
  wr<T>(f[ip->a], neg<T>(rd<T>(f[ip->b])));      \
  NEXT();                                        \
  L_ABS_##T:                                     \
  wr<T>(f[ip->a], abs_of<T>(rd<T>(f[ip->b])));   \
  NEXT();
  SYNCPLC_ST_NUM_TYPES(ARITH)
#undef ARITH

#define CMP(T)                                                          \
  L_EQ_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) == rd<T>(f[ip->c])); NEXT(); \
  L_NE_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) != rd<T>(f[ip->c])); NEXT(); \
  L_LT_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) < rd<T>(f[ip->c])); NEXT();  \
  L_LE_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) <= rd<T>(f[ip->c])); NEXT(); \
  L_GT_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) > rd<T>(f[ip->c])); NEXT();  \
  L_GE_##T: wr<bool>(f[ip->a], rd<T>(f[ip->b]) >= rd<T>(f[ip->c])); NEXT(); \
  L_JNLT_##T: if (!(rd<T>(f[ip->a]) < rd<T>(f[ip->b]))) JUMP(ip->d); NEXT();  \
  L_JNLE_##T: if (!(rd<T>(f[ip->a]) <= rd<T>(f[ip->b]))) JUMP(ip->d); NEXT(); \
  L_JNGT_##T: if (!(rd<T>(f[ip->a]) > rd<T>(f[ip->b]))) JUMP(ip->d); NEXT();  \
  L_JNGE_##T: if (!(rd<T>(f[ip->a]) >= rd<T>(f[ip->b]))) JUMP(ip->d); NEXT(); \
  L_JNEQ_##T: if (!(rd<T>(f[ip->a]) == rd<T>(f[ip->b]))) JUMP(ip->d); NEXT(); \
  L_JNNE_##T: if (!(rd<T>(f[ip->a]) != rd<T>(f[ip->b]))) JUMP(ip->d); NEXT(); \
  L_WIDEN_TO_I16_##T: wr<I16>(f[ip->a], static_cast<I16>(rd<T>(f[ip->b]))); NEXT(); \
  L_WIDEN_TO_I32_##T: wr<I32>(f[ip->a], static_cast<I32>(rd<T>(f[ip->b]))); NEXT(); \
  L_WIDEN_TO_I64_##T: wr<I64>(f[ip->a], static_cast<I64>(rd<T>(f[ip->b]))); NEXT(); \
  L_WIDEN_TO_F32_##T: wr<F32>(f[ip->a], static_cast<F32>(rd<T>(f[ip->b]))); NEXT(); \
  L_WIDEN_TO_F64_##T: wr<F64>(f[ip->a], static_cast<F64>(rd<T>(f[ip->b]))); NEXT();
  SYNCPLC_ST_NUM_TYPES(CMP)
#undef CMP

  // FOR: a control variable, b end, c step (all of the control variable's
  // type, end and step evaluated once). Counted in 128 bits: the loop ends
  // without the control variable wrapping past the end.
#define FOR(T)                                                                        \
  L_FOR_ENTER_##T: {                                                                  \
    const T i = rd<T>(f[ip->a]), e = rd<T>(f[ip->b]), s = rd<T>(f[ip->c]);            \
    if (!is_negative(s) ? i > e : i < e) JUMP(ip->d);                                  \
    NEXT();                                                                           \
  }                                                                                   \
  L_FOR_NEXT_##T: {                                                                   \
    const __int128 i = rd<T>(f[ip->a]), e = rd<T>(f[ip->b]), s = rd<T>(f[ip->c]);     \
    if (s > 0 ? e - i < s : s < 0 ? i - e < -s : false) NEXT();                        \
    wr<T>(f[ip->a], static_cast<T>(i + s));                                           \
    COUNT_BACKWARD_JUMP();                                                            \
    JUMP(ip->d);                                                                      \
  }
  SYNCPLC_ST_INT_TYPES(FOR)
#undef FOR

  // FOR with the step 1 (the common case): a < b cannot wrap a + 1.
#define FOR_INC(T)                                  \
  L_FOR_INC_##T: {                                  \
    const T i = rd<T>(f[ip->a]);                    \
    if (!(i < rd<T>(f[ip->b]))) NEXT();             \
    wr<T>(f[ip->a], static_cast<T>(i + 1));         \
    COUNT_BACKWARD_JUMP();                                                            \
    JUMP(ip->d);                                    \
  }
  SYNCPLC_ST_INT_TYPES(FOR_INC)
#undef FOR_INC

  // Checked one-cell elements, typed by the index (no switch on its type;
  // the code generator makes these for one-dimensional arrays of one-cell
  // elements only, so the stride is 1).
#define INDEXED(T)                                                                   \
  L_LDX_##T: {                                                                       \
    const IndexCheck& k = m.indexes[ip->d];                                          \
    const std::int64_t v = index_as_i64<T>(f[ip->c]);                                \
    const std::uint64_t at = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(k.low); \
    if (at >= k.count) {                                                             \
      vm.fault(k.site, static_cast<double>(v));                                      \
      f[ip->a].raw = 0;                                                              \
    } else {                                                                         \
      f[ip->a] = f[ip->b + at];                                                      \
    }                                                                                \
    NEXT();                                                                          \
  }                                                                                  \
  L_STX_##T: {                                                                       \
    const IndexCheck& k = m.indexes[ip->d];                                          \
    const std::int64_t v = index_as_i64<T>(f[ip->c]);                                \
    const std::uint64_t at = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(k.low); \
    if (at >= k.count) vm.fault(k.site, static_cast<double>(v));                     \
    else f[ip->a + at] = f[ip->b];                                                   \
    NEXT();                                                                          \
  }
  SYNCPLC_ST_INT_TYPES(INDEXED)
#undef INDEXED

#define FUSED(T)                                                                                   \
  L_MULADD_##T:                                                                                    \
  wr<T>(f[ip->a], add<T>(rounded<T>(mul<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c]))), rd<T>(f[ip->d])));  \
  NEXT();                                                                                          \
  L_ADDMUL_##T:                                                                                    \
  wr<T>(f[ip->a], add<T>(rd<T>(f[ip->d]), rounded<T>(mul<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c])))));  \
  NEXT();                                                                                          \
  L_MULSUB_##T:                                                                                    \
  wr<T>(f[ip->a], sub<T>(rounded<T>(mul<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c]))), rd<T>(f[ip->d])));  \
  NEXT();                                                                                          \
  L_SUBMUL_##T:                                                                                    \
  wr<T>(f[ip->a], sub<T>(rd<T>(f[ip->d]), rounded<T>(mul<T>(rd<T>(f[ip->b]), rd<T>(f[ip->c])))));  \
  NEXT();                                                                                          \
  L_CLAMP_##T: {                                                                                   \
    const T x = rd<T>(f[ip->a]);                                                                   \
    const bool over = x > rd<T>(f[ip->c]), under = x < rd<T>(f[ip->b]);                            \
    /* the branch taken first wins when the bounds cross (lo > hi), as the IF it replaces */       \
    if (ip->d == 0 ? over : (over && !under)) f[ip->a] = f[ip->c];                                 \
    else if (under) f[ip->a] = f[ip->b];                                                           \
    NEXT();                                                                                        \
  }
  SYNCPLC_ST_NUM_TYPES(FUSED)
#undef FUSED
#undef BIN
#undef COUNT_BACKWARD_JUMP
#undef DISPATCH
#undef NEXT
#undef JUMP
}

}  // namespace

void Vm::fault(std::uint32_t site, double value) noexcept {
  ++faults;
  last_fault = module->sites[site].message;
  if (ctx) ctx->fault(last_fault, value);
}

bool run(Vm& vm, std::uint32_t pou, Cell* frame) noexcept { return run(vm, vm.module->pous[pou], frame); }

bool run(Vm& vm, const CompiledPou& p, Cell* frame) noexcept {
  if (p.temp_cells)
    std::memcpy(frame + p.temp_begin, p.image.data() + p.temp_begin, p.temp_cells * sizeof(Cell));
  if (p.native) return p.native(&vm, frame) != 0;
  bool ok = true;
  exec<false>(vm, &p, frame, &ok, nullptr);
  return ok;
}

std::uint32_t step(Vm* vm, const CompiledPou* pou, Cell* frame, std::uint32_t pc) noexcept {
  bool ok = true;
  const Insn* at = pou->code.data() + pc;
  exec<true>(*vm, pou, frame, &ok, &at);
  if (!ok) return kStepStopped;
  if (!at) return kStepHalted;
  return static_cast<std::uint32_t>(at - pou->code.data());
}

namespace {

// The forward jumps whose d is their target (JMPB and FOR_NEXT/FOR_INC are
// backward and count against the budget: left as they are).
bool forward_jump(Op op) {
  return op == Op::JMP || op == Op::JZ || op == Op::JNZ || (op >= Op::JNLT_I8 && op <= Op::JNNE_F64) ||
         (op >= Op::FOR_ENTER_I8 && op <= Op::FOR_ENTER_U64);
}

// Jump threading: the end of an inner IF jumps to the end of the outer one,
// an ELSIF branch to the end of the POU. A forward jump whose target is a
// JMP goes to where that JMP goes; a JMP to a HALT is a HALT. Control flow
// only: no instruction with an effect is skipped or moved.
void thread_jumps(std::vector<Insn>& code) {
  const auto n = static_cast<std::uint32_t>(code.size());
  auto final_target = [&](std::uint32_t t) {
    for (int hops = 0; hops < 64 && t < n && code[t].op == Op::JMP && code[t].d != t; ++hops) t = code[t].d;
    return t;
  };
  for (Insn& i : code) {
    if (!forward_jump(i.op)) continue;
    i.d = final_target(i.d);
    if (i.op == Op::JMP && i.d < n && code[i.d].op == Op::HALT) i.op = Op::HALT;
  }
}

}  // namespace

void finalize(Module& m, Engine engine) {
  Vm none;
  bool ok = true;
  const void* const* labels = exec<false>(none, nullptr, nullptr, &ok, nullptr);
  for (CompiledPou& p : m.pous) {
    thread_jumps(p.code);
    for (Insn& i : p.code) i.handler = labels[static_cast<int>(i.op)];
  }
  set_engine(m, engine);
}

}  // namespace syncplc::st::vm
