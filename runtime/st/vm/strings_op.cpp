// The string instruction: dispatches a StringCall to st_string.hpp for
// STRING (char) or WSTRING (char16_t) and turns a non-Ok status into the
// call site's fault (the result stays the function's defined one).
#include "runtime/st/vm/strings_op.hpp"

#include "runtime/st/vm/st_string.hpp"

namespace syncplc::st::vm {

namespace {

template <StringChar C>
StringStatus apply(const Module& m, Cell* f, const StringCall& s) noexcept {
  Cell* dst = f + s.dst;
  const Cell* a0 = f + s.args[0];
  const Cell* a1 = f + s.args[1];
  const auto i64 = [&](int k) { return f[s.args[k]].get<std::int64_t>(); };
  const auto compare = [&] { return str_compare<C>(a0, a1); };
  switch (s.fn) {
    case StringFn::Assign: return str_assign<C>(dst, s.capacity, a0);
    case StringFn::Literal: {
      const std::string& t = m.texts[s.text];
      if constexpr (sizeof(C) == 2) return wstr_set_utf8(dst, s.capacity, t.data(), t.size());
      else return str_set(dst, s.capacity, t.data(), t.size());
    }
    case StringFn::Concat: return str_concat<C>(dst, s.capacity, a0, a1);
    case StringFn::Left: return str_left<C>(dst, s.capacity, a0, i64(1));
    case StringFn::Right: return str_right<C>(dst, s.capacity, a0, i64(1));
    case StringFn::Mid: return str_mid<C>(dst, s.capacity, a0, i64(1), i64(2));
    case StringFn::Insert: return str_insert<C>(dst, s.capacity, a0, a1, i64(2));
    case StringFn::Delete: return str_delete<C>(dst, s.capacity, a0, i64(1), i64(2));
    case StringFn::Replace: return str_replace<C>(dst, s.capacity, a0, a1, i64(2), i64(3));
    // LEN and FIND are INT: a length or position beyond 32767 saturates (a
    // STRING's capacity is at most kMaxStringLength, which fits).
    case StringFn::Len: dst->set<std::int16_t>(static_cast<std::int16_t>(str_len(a0))); return StringStatus::Ok;
    case StringFn::Find:
      dst->set<std::int16_t>(static_cast<std::int16_t>(str_find<C>(a0, a1)));
      return StringStatus::Ok;
    case StringFn::Eq: dst->set<bool>(compare() == 0); return StringStatus::Ok;
    case StringFn::Ne: dst->set<bool>(compare() != 0); return StringStatus::Ok;
    case StringFn::Lt: dst->set<bool>(compare() < 0); return StringStatus::Ok;
    case StringFn::Le: dst->set<bool>(compare() <= 0); return StringStatus::Ok;
    case StringFn::Gt: dst->set<bool>(compare() > 0); return StringStatus::Ok;
    case StringFn::Ge: dst->set<bool>(compare() >= 0); return StringStatus::Ok;
    case StringFn::ToString: return to_string<C>(s.type, *a0, dst, s.capacity);
    case StringFn::FromString: return from_string<C>(s.type, a0, dst);
  }
  return StringStatus::Ok;
}

}  // namespace

void string_op(Vm& vm, Cell* frame, const StringCall& call) noexcept {
  const StringStatus st = call.wide ? apply<char16_t>(*vm.module, frame, call) : apply<char>(*vm.module, frame, call);
  if (st != StringStatus::Ok) vm.fault(call.site);
}

}  // namespace syncplc::st::vm
