// Paths of instance variables (var_path.hpp).
#include "runtime/st/vm/var_path.hpp"

#include <cctype>
#include <vector>

#include <fmt/format.h>

#include "runtime/core/block.hpp"
#include "runtime/core/closest_name.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/vm/st_string.hpp"

namespace syncplc::st::vm {

namespace {

std::string suggest(std::string_view name, const std::vector<std::string_view>& names) {
  const std::string best = syncplc::closest_name(name, names);
  return best.empty() ? "" : " (did you mean " + best + "?)";
}

bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

}  // namespace

BuiltinLayout builtin_layout(const FbType& fb) {
  BuiltinLayout l;
  l.pin_at.reserve(fb.pins.size());
  for (const Pin& p : fb.pins) {
    l.pin_at.push_back(l.cells);
    const std::uint32_t n = p.type->kind == Type::Kind::Array ? static_cast<std::uint32_t>(p.type->element_count()) : 1;
    l.cells += p.dir == PinDir::InOut ? 1 + n : n;
  }
  return l;
}

std::uint32_t frame_cells_of(const Module& m, const Type* t) {
  switch (t->kind) {
    case Type::Kind::String: return static_cast<std::uint32_t>(string_cells(t->length, t->wide));
    case Type::Kind::Array: return static_cast<std::uint32_t>(t->element_count()) * frame_cells_of(m, t->element);
    case Type::Kind::Struct: {
      std::uint32_t n = 0;
      for (const Field& f : t->fields) n += frame_cells_of(m, f.type);
      return n;
    }
    case Type::Kind::FunctionBlock: {
      if (t->fb->builtin) return builtin_layout(*t->fb).cells;
      const int p = m.find(t->fb->name);
      return p < 0 ? 1 : std::max<std::uint32_t>(m.pous[static_cast<std::size_t>(p)].frame_cells, 1);
    }
    default: return 1;
  }
}

std::optional<VarRef> resolve_path(const Module& m, std::uint32_t pou, std::string_view path, std::string* error) {
  std::size_t i = 0;
  auto ident = [&]() {
    const std::size_t start = i;
    while (i < path.size() && ident_char(path[i])) ++i;
    return path.substr(start, i - start);
  };
  auto fail = [&](std::string why) -> std::optional<VarRef> {
    if (error) *error = std::move(why);
    return std::nullopt;
  };
  const std::string_view first = ident();
  if (first.empty()) return fail(fmt::format("'{}' is not a variable path", path));
  const CompiledPou& p = m.pous[pou];
  VarRef r;
  const VarSlot* slot = nullptr;
  std::vector<std::string_view> names;
  for (const VarSlot& v : p.vars) {
    names.push_back(v.name);
    if (same_name(v.name, first)) slot = &v;
  }
  if (!slot) return fail(fmt::format("{} has no variable '{}'{}", p.name, first, suggest(first, names)));
  r.at = slot->at;
  r.type = slot->type;
  r.reference = slot->scope == static_cast<int>(VarScope::InOut) || slot->scope == static_cast<int>(VarScope::External);
  r.temp = slot->scope == static_cast<int>(VarScope::Temp);
  r.constant = slot->constant;
  while (i < path.size()) {
    if (r.bit >= 0) return fail(fmt::format("'{}': nothing follows a bit", path));
    if (r.reference) return fail(fmt::format("'{}': {} is a reference (VAR_IN_OUT or VAR_EXTERNAL); name what it refers to",
                                             path, path.substr(0, i)));
    const Type* t = r.type;
    if (path[i] == '.') {
      ++i;
      if (i < path.size() && std::isdigit(static_cast<unsigned char>(path[i]))) {
        int bit = 0;
        while (i < path.size() && std::isdigit(static_cast<unsigned char>(path[i]))) bit = bit * 10 + (path[i++] - '0');
        const auto s = t->scalar();
        if (!s || !is_bits(*s) || *s == Elem::BOOL || bit >= bits(*s))
          return fail(fmt::format("'{}': bit {} of a {}", path, bit, t->name));
        r.bit = bit;
        continue;
      }
      const std::string_view name = ident();
      names.clear();
      if (t->kind == Type::Kind::Struct) {
        std::uint32_t off = 0;
        const Field* found = nullptr;
        for (const Field& f : t->fields) {
          names.push_back(f.name);
          if (same_name(f.name, name)) {
            found = &f;
            break;
          }
          off += frame_cells_of(m, f.type);
        }
        if (!found) return fail(fmt::format("{} has no field '{}'{}", t->name, name, suggest(name, names)));
        r.at += off;
        r.type = found->type;
        continue;
      }
      if (t->kind == Type::Kind::FunctionBlock) {
        if (t->fb->builtin) {
          int k = 0;
          const Pin* found = nullptr;
          for (const Pin& pin : t->fb->pins) {
            names.push_back(pin.name);
            if (same_name(pin.name, name)) {
              found = &pin;
              break;
            }
            ++k;
          }
          if (!found) return fail(fmt::format("{} has no pin '{}'{}", t->name, name, suggest(name, names)));
          r.at += builtin_layout(*t->fb).pin_at[static_cast<std::size_t>(k)];
          r.type = found->type;
          continue;
        }
        const int fp = m.find(t->fb->name);
        if (fp < 0) return fail(fmt::format("'{}': {} is not compiled", path, t->name));
        const VarSlot* v = nullptr;
        for (const VarSlot& x : m.pous[static_cast<std::size_t>(fp)].vars) {
          names.push_back(x.name);
          if (same_name(x.name, name)) v = &x;
        }
        if (!v) return fail(fmt::format("{} has no variable '{}'{}", t->name, name, suggest(name, names)));
        r.at += v->at;
        r.type = v->type;
        r.reference = v->scope == static_cast<int>(VarScope::InOut) || v->scope == static_cast<int>(VarScope::External);
        r.temp = r.temp || v->scope == static_cast<int>(VarScope::Temp);
        r.constant = r.constant || v->constant;
        continue;
      }
      return fail(fmt::format("'{}': a {} has no fields", path, t->name));
    }
    if (path[i] == '[') {
      if (t->kind != Type::Kind::Array) return fail(fmt::format("'{}': a {} is not an array", path, t->name));
      ++i;
      std::uint64_t offset = 0;
      std::uint32_t stride = frame_cells_of(m, t->element);
      std::vector<std::int64_t> idx;
      while (true) {
        while (i < path.size() && path[i] == ' ') ++i;
        bool neg = false;
        if (i < path.size() && path[i] == '-') neg = true, ++i;
        if (i >= path.size() || !std::isdigit(static_cast<unsigned char>(path[i])))
          return fail(fmt::format("'{}': an index must be an integer", path));
        std::int64_t v = 0;
        while (i < path.size() && std::isdigit(static_cast<unsigned char>(path[i]))) {
          if (v > 1'000'000'000'000LL) return fail(fmt::format("'{}': index too large", path));
          v = v * 10 + (path[i++] - '0');
        }
        idx.push_back(neg ? -v : v);
        while (i < path.size() && path[i] == ' ') ++i;
        if (i < path.size() && path[i] == ',') {
          ++i;
          continue;
        }
        if (i < path.size() && path[i] == ']') {
          ++i;
          break;
        }
        return fail(fmt::format("'{}': ']' expected", path));
      }
      if (idx.size() != t->dims.size())
        return fail(fmt::format("'{}': {} has {} dimension(s)", path, t->name, t->dims.size()));
      for (std::size_t k = t->dims.size(); k-- > 0;) {
        const ArrayDim& d = t->dims[k];
        if (idx[k] < d.low || idx[k] > d.high)
          return fail(fmt::format("'{}': index {} is outside {}..{}", path, idx[k], d.low, d.high));
        offset += static_cast<std::uint64_t>(idx[k] - d.low) * stride;
        stride *= static_cast<std::uint32_t>(d.count());
      }
      r.at += static_cast<std::uint32_t>(offset);
      r.type = t->element;
      continue;
    }
    return fail(fmt::format("'{}': unexpected '{}'", path, path[i]));
  }
  return r;
}

}  // namespace syncplc::st::vm
