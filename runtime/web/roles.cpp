#include "runtime/web/roles.hpp"

namespace syncplc::web {

std::string_view role_name(Role r) {
  switch (r) {
    case Role::Viewer: return "viewer";
    case Role::Operator: return "operator";
    case Role::Engineer: return "engineer";
  }
  return "viewer";
}

std::optional<Role> parse_role(std::string_view s) {
  if (s == "viewer") return Role::Viewer;
  if (s == "operator") return Role::Operator;
  if (s == "engineer") return Role::Engineer;
  return std::nullopt;
}

}  // namespace syncplc::web
