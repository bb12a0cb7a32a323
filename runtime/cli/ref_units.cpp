#include "runtime/cli/ref_units.hpp"

#include "runtime/cli/online_values.hpp"

namespace syncplc::cli {
namespace {

std::string unit_of(const nlohmann::json& j) {
  return j.is_object() && j.contains("unit") && j["unit"].is_string() ? j["unit"].get<std::string>() : "";
}

}  // namespace

std::map<std::string, std::string> ref_units(ApiClient& api, const std::vector<std::string>& refs) {
  std::map<std::string, std::string> tag_units;             // tag -> unit
  std::map<std::string, nlohmann::json> blocks;             // instance -> GET /blocks/INSTANCE
  std::map<std::string, std::string> out;
  for (const auto& ref : refs) {
    const RefParts p = split_ref(ref);
    if (p.instance.empty()) {
      if (!tag_units.count(p.name)) {
        const ApiAnswer a = api.request("GET", "/tags/" + url_encode(p.name));
        tag_units[p.name] = a.status == 200 ? unit_of(a.json) : "";
      }
      out[ref] = tag_units[p.name];
      continue;
    }
    if (!blocks.count(p.instance)) {
      const ApiAnswer a = api.request("GET", "/blocks/" + url_encode(p.instance));
      blocks[p.instance] = a.status == 200 ? a.json : nlohmann::json();
    }
    out[ref] = "";
    const nlohmann::json& b = blocks[p.instance];
    if (b.is_object() && b.contains("pins") && b["pins"].is_array())
      for (const auto& pin : b["pins"])
        if (pin.is_object() && pin.value("name", "") == p.name) out[ref] = unit_of(pin);
  }
  return out;
}

std::string refs_query(const std::vector<std::string>& refs) {
  std::string q;
  for (const auto& r : refs) q += (q.empty() ? "" : ",") + url_encode(r);
  return q;
}

}  // namespace syncplc::cli
