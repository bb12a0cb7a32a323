// Who may do what over the HTTP API (docs/http-api.md, "Authentication and
// roles"): viewer < operator < engineer, each role allowed what the one
// below it is, and more.
#pragma once

#include <optional>
#include <string_view>

namespace syncplc::web {

enum class Role : int { Viewer = 0, Operator = 1, Engineer = 2 };

// "viewer", "operator", "engineer".
std::string_view role_name(Role r);
std::optional<Role> parse_role(std::string_view s);
// Whether `have` may do what needs `need`.
constexpr bool role_allows(Role have, Role need) { return static_cast<int>(have) >= static_cast<int>(need); }

}  // namespace syncplc::web
