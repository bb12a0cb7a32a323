#include "runtime/cli/online_values.hpp"

#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <regex>

namespace syncplc::cli {

nlohmann::json value_from_command_line(std::string_view text) {
  const std::string s(text);
  static const std::regex integer(R"(^[+-]?[0-9]+$)");
  static const std::regex real(R"(^[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?$)");
  if (std::regex_match(s, integer)) {
    errno = 0;
    const long long i = std::strtoll(s.c_str(), nullptr, 10);
    if (errno == 0) return static_cast<std::int64_t>(i);
    errno = 0;
    const unsigned long long u = std::strtoull(s.c_str(), nullptr, 10);
    if (errno == 0 && s[0] != '-') return static_cast<std::uint64_t>(u);
    return s;  // beyond 64 bits: the server says what is wrong with it
  }
  if (std::regex_match(s, real)) {
    errno = 0;
    const double d = std::strtod(s.c_str(), nullptr);
    if (errno == 0) return d;
    return s;
  }
  std::string upper;
  for (char c : s) upper += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (upper == "TRUE") return true;
  if (upper == "FALSE") return false;
  if (!s.empty() && s.front() == '[') {
    auto j = nlohmann::json::parse(s, nullptr, /*allow_exceptions=*/false);
    if (j.is_array()) return j;
  }
  return s;
}

std::string format_value(const nlohmann::json& v) {
  if (v.is_boolean()) return v.get<bool>() ? "TRUE" : "FALSE";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "?";
  if (v.is_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + format_value(v[i]);
    return out + "]";
  }
  return v.dump();  // numbers: nlohmann writes the shortest text that reads back exactly
}

bool any_forced(const nlohmann::json& forced) {
  if (forced.is_boolean()) return forced.get<bool>();
  if (forced.is_array())
    for (const auto& f : forced)
      if (f.is_boolean() && f.get<bool>()) return true;
  return false;
}

RefParts split_ref(std::string_view ref) {
  std::string_view base = ref.substr(0, ref.find('['));
  const auto dot = base.find('.');
  if (dot == std::string_view::npos) return {"", std::string(base)};
  return {std::string(base.substr(0, dot)), std::string(base.substr(dot + 1))};
}

}  // namespace syncplc::cli
