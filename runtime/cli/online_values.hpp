// Values between the command line and the HTTP API: what `syncplc write`
// and `force` send for the text a user typed, and how `read` and `watch`
// show what comes back.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace syncplc::cli {

// A number becomes a JSON number (an integer stays an integer, exactly),
// TRUE/FALSE (any case) a boolean, a JSON array ("[1, 2.5, 3]") an array
// for a whole array tag; anything else is sent as text for the server's IEC
// parser: "T#5ms", "1500 mm", "16#FF", an integer too large for 64 bits.
nlohmann::json value_from_command_line(std::string_view text);

// As IEC text: TRUE/FALSE, numbers in their shortest exact form, TIME and
// large integers as the server wrote them ("T#1s500ms"), arrays in
// brackets; null (no value yet: a pin whose monitoring just started) is "?".
std::string format_value(const nlohmann::json& v);

// Whether a "forced" flag of /values or /stream says forced: a boolean, or
// one per element of an array (any of them).
bool any_forced(const nlohmann::json& forced);

// The parts of a ref: "pos[2]" -> tag "pos"; "sync.x[2]" -> instance
// "sync", pin "x". instance is "" for a tag.
struct RefParts {
  std::string instance, name;
};
RefParts split_ref(std::string_view ref);

}  // namespace syncplc::cli
