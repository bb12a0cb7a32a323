// The unit each ref of `read` and `watch` is shown with: a tag's from GET
// /tags/NAME, a pin's from GET /blocks/INSTANCE (one request per tag or
// instance named). A unit is decoration: a ref whose lookup fails shows none.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "runtime/cli/api_client.hpp"

namespace syncplc::cli {

// ref -> unit ("" for none); every ref is a key.
std::map<std::string, std::string> ref_units(ApiClient& api, const std::vector<std::string>& refs);

// "a,b%5B2%5D,inst.pin": refs for a query, commas kept as the separator.
std::string refs_query(const std::vector<std::string>& refs);

}  // namespace syncplc::cli
