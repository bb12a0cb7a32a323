#include "runtime/web/json_values.hpp"

#include <cmath>

namespace syncplc::web {
namespace {

constexpr std::int64_t kExactInJson = std::int64_t{1} << 53;  // doubles hold every integer up to here

}  // namespace

nlohmann::json cell_json(IecType t, Cell c) {
  if (t == IecType::BOOL) return c.raw != 0;
  if (t == IecType::TIME) return format_value(t, c);
  if (is_real(t)) {
    const double v = cell_as_double(t, c);
    if (!std::isfinite(v)) return format_value(t, c);
    return v;
  }
  if (is_signed_integer(t)) {
    const auto v = static_cast<std::int64_t>(cell_as_double(t, c));
    if (t == IecType::LINT) {
      const auto exact = c.get<std::int64_t>();
      if (exact > kExactInJson || exact < -kExactInJson) return format_value(t, c);
      return exact;
    }
    return v;
  }
  // Unsigned integers and bit strings.
  if (t == IecType::ULINT || t == IecType::LWORD) {
    const auto exact = c.get<std::uint64_t>();
    if (exact > static_cast<std::uint64_t>(kExactInJson)) return format_value(t, c);
    return exact;
  }
  return static_cast<std::uint64_t>(cell_as_double(t, c));
}

nlohmann::json cells_json(IecType t, const Cell* c, std::uint32_t n, bool array) {
  if (!array) return cell_json(t, c[0]);
  nlohmann::json a = nlohmann::json::array();
  for (std::uint32_t i = 0; i < n; ++i) a.push_back(cell_json(t, c[i]));
  return a;
}

std::optional<std::string> value_text(const nlohmann::json& v, std::string* error) {
  if (v.is_boolean()) return std::string(v.get<bool>() ? "TRUE" : "FALSE");
  if (v.is_number_integer()) return v.is_number_unsigned() ? std::to_string(v.get<std::uint64_t>()) : std::to_string(v.get<std::int64_t>());
  if (v.is_number_float()) return v.dump();  // shortest text that reads back as the same double
  if (v.is_string()) return v.get<std::string>();
  *error = std::string("a value must be a number, true/false or text such as \"T#5ms\", not ") +
           (v.is_null() ? "null" : v.is_array() ? "an array" : "an object");
  return std::nullopt;
}

std::optional<nlohmann::json> parse_json_body(const std::string& body, std::string* error) {
  try {
    return nlohmann::json::parse(body);
  } catch (const nlohmann::json::parse_error& e) {
    *error = "the body is not valid JSON (at byte " + std::to_string(e.byte) + ")";
  } catch (const nlohmann::json::out_of_range& e) {
    // nlohmann refuses a number beyond a double (1e999) with out_of_range
    // 406 "number overflow parsing '1e999'", which names the number.
    std::string what = e.what();
    const auto quote = what.find('\'');
    *error = "a number in the body is too large for a 64-bit float" +
             (quote == std::string::npos ? std::string() : " (" + what.substr(quote) + ")");
  } catch (const nlohmann::json::exception& e) {
    *error = std::string("the body is not valid JSON (") + e.what() + ")";
  }
  return std::nullopt;
}

}  // namespace syncplc::web
