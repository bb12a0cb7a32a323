// Values between the process image and JSON (docs/http-api.md, "Reading"):
// BOOL as true/false, numbers as numbers, what JSON cannot carry exactly
// (64-bit integers past 2^53, TIME, NaN and infinities) as IEC text.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

#include "runtime/core/iec_type.hpp"

namespace syncplc::web {

nlohmann::json cell_json(IecType t, Cell c);
// n cells: one value, or an array of n when `array`.
nlohmann::json cells_json(IecType t, const Cell* c, std::uint32_t n, bool array);

// A written value as the text the one parser of written values takes
// (parse_value_in_unit): numbers as JSON wrote them, booleans as TRUE/FALSE,
// strings as they are ("T#5ms", "1500 mm", "16#FF"). Nullopt with `error`
// for objects, arrays and null.
std::optional<std::string> value_text(const nlohmann::json& v, std::string* error);

// A request body as JSON; nullopt with `error` saying what is wrong and
// where ("the body is not valid JSON (at byte 12)", "a number at byte 11 is
// too large for a double (1e999)"). Never throws: no client input makes a 5xx.
std::optional<nlohmann::json> parse_json_body(const std::string& body, std::string* error);

}  // namespace syncplc::web
