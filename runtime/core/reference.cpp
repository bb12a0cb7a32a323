#include "runtime/core/reference.hpp"

#include <cctype>
#include <charconv>

namespace syncplc {

std::optional<Reference> parse_reference(std::string_view text, std::string* error) {
  auto fail = [&](const std::string& why) -> std::optional<Reference> {
    if (error) *error = why;
    return std::nullopt;
  };
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.remove_suffix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front()))) text.remove_prefix(1);
  Reference r;
  r.text = std::string(text);
  r.base = r.text;
  if (auto lb = text.find('['); lb != std::string_view::npos) {
    if (text.back() != ']') return fail("bad element reference '" + r.text + "'");
    std::string_view num = text.substr(lb + 1, text.size() - lb - 2);
    std::int64_t i = 0;
    // from_chars fails on a number that does not fit 64 bits (no wrap).
    auto [p, ec] = std::from_chars(num.data(), num.data() + num.size(), i);
    if (num.empty() || ec != std::errc() || p != num.data() + num.size()) return fail("bad array index in '" + r.text + "'");
    r.index = i;
    r.base = std::string(text.substr(0, lb));
  }
  if (auto dot = r.base.find('.'); dot != std::string::npos) {
    r.owner = r.base.substr(0, dot);
    r.member = r.base.substr(dot + 1);
  } else {
    r.owner = r.base;
  }
  return r;
}

std::optional<std::uint32_t> element_of(const Reference& r, std::int64_t lower, std::uint32_t length, std::string* error) {
  std::int64_t rel = 0;
  if (!r.index || __builtin_sub_overflow(*r.index, lower, &rel) || rel < 0 || rel >= static_cast<std::int64_t>(length)) {
    if (error) {
      // lower + length - 1 fits: a tag's bounds were checked at load.
      *error = "index " + (r.index ? std::to_string(*r.index) : std::string("?")) + " is outside " + r.base + "[" +
               std::to_string(lower) + ".." + std::to_string(lower + (static_cast<std::int64_t>(length) - 1)) + "]";
    }
    return std::nullopt;
  }
  return static_cast<std::uint32_t>(rel);
}

std::string unknown_instance_message(const std::string& instance) { return "unknown block instance '" + instance + "'"; }

std::string unknown_tag_message(const std::string& name) { return "unknown tag or instance.pin '" + name + "'"; }

std::string pin_names(const BlockTypeInfo& type) {
  std::string names;
  for (const auto& p : type.pins)
    if (p.name.empty() || p.name.front() != '(')  // not the hidden "(variables)" of an ST POU
      names += (names.empty() ? "" : ", ") + p.name;
  return names;
}

std::string no_pin_message(const std::string& instance, const BlockTypeInfo& type, const std::string& pin) {
  return "block " + instance + " (" + type.name + ") has no pin '" + pin + "' (" + pin_names(type) + ")";
}

}  // namespace syncplc
