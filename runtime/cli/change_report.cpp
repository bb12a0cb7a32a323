#include "runtime/cli/change_report.hpp"

#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/cli/online_values.hpp"

namespace syncplc::cli {
namespace {

using nlohmann::json;

std::string str(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
}

// "filler, capper" of a report's list (names, or objects with a name).
std::string names(const json& list) {
  std::string out;
  for (const auto& x : list) {
    const std::string n = x.is_string() ? x.get<std::string>() : x.is_object() && x.contains("name") ? str(x, "name") : x.dump();
    out += (out.empty() ? "" : ", ") + n;
  }
  return out;
}

void print_report(const json& a) {
  const json report = a.is_object() ? a.value("report", json::object()) : json::object();
  std::string summary = str(a, "summary");
  if (summary.empty()) summary = str(report, "summary");
  std::cout << (a.contains("version") ? "version " + a["version"].dump() + " running" : std::string("accepted"));
  if (!summary.empty()) std::cout << ": " << summary;
  std::cout << "\n";
  if (a.contains("lines") && a["lines"].is_array() && !a["lines"].empty()) {
    // The server's own report lines, as a local `syncplc reload` prints them.
    for (const auto& l : a["lines"]) std::cout << "  " << (l.is_string() ? l.get<std::string>() : l.dump()) << "\n";
    return;
  }
  for (const char* k : {"kept", "retuned", "rewired", "new", "removed"})
    if (report.contains(k) && report[k].is_array() && !report[k].empty())
      std::cout << "  " << k << std::string(9 - std::string(k).size(), ' ') << names(report[k]) << "\n";
}

}  // namespace

int print_change_answer(const ApiClient& api, const ApiAnswer& a, const std::string& what, bool check_only,
                        int rejected) {
  const json& j = a.json;
  if (a.status >= 200 && a.status <= 299) {
    if (check_only) std::cout << what << ": no errors (checked by the PLC at " << api.url() << "; nothing changed)\n";
    else print_report(j);
    return kExitOk;
  }
  if (a.status == 400 && j.is_object() && j.contains("errors") && j["errors"].is_array() && !j["errors"].empty()) {
    std::cout.flush();
    for (const auto& e : j["errors"]) {
      if (e.is_string()) std::cerr << e.get<std::string>() << "\n";
      else if (!str(e, "where").empty()) std::cerr << str(e, "where") << ": " << str(e, "message") << "\n";
      else std::cerr << str(e, "message") << "\n";
    }
    const std::size_t n = j["errors"].size();
    std::cerr << what << ": " << n << (n == 1 ? " error" : " errors")
              << (check_only ? "" : ", project not loaded (the running program goes on unchanged)") << "\n";
    return rejected;
  }
  api.refuse(a);
}

}  // namespace syncplc::cli
