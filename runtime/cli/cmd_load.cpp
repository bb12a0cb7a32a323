// syncplc load, rollback, and reload --url: project changes of a running
// `syncplc run` through its HTTP API (docs/http-api.md, "Changing the PLC").
#include <iostream>

#include "runtime/cli/api_client.hpp"
#include "runtime/cli/change_report.hpp"
#include "runtime/cli/commands.hpp"
#include "runtime/cli/project_upload.hpp"

namespace syncplc::cli {

int cmd_load(const std::string& project, bool check_only, const OnlineOptions& o) {
  return run_online(check_only ? "load --check" : "load", [&] {
    std::string err;
    auto up = collect_project(project, &err);
    if (!up) throw ApiError(kExitInvalid, err);
    nlohmann::json body = {{"main", up->main}, {"files", nlohmann::json::object()}};
    for (const auto& [name, text] : up->files) body["files"][name] = text;
    try {
      (void)body.dump();  // JSON carries text only
    } catch (const nlohmann::json::type_error&) {
      throw ApiError(kExitInvalid, project + ": a file of the project is not UTF-8 text");
    }
    auto api = connect_api(o);
    const ApiAnswer a = api->request("POST", check_only ? "/projects/check" : "/projects/load", &body);
    return print_change_answer(*api, a, project, check_only, kExitInvalid);
  });
}

int cmd_rollback(std::int64_t version, const OnlineOptions& o) {
  return run_online("rollback", [&] {
    auto api = connect_api(o);
    const nlohmann::json body = {{"version", version}};
    const ApiAnswer a = api->request("POST", "/projects/rollback", &body);
    return print_change_answer(*api, a, "version " + std::to_string(version), false, kExitInvalid);
  });
}

// A rejected project exits 1 here, as a local `syncplc reload` does.
int reload_through_api(std::int64_t version, const OnlineOptions& o) {
  return run_online("reload", [&] {
    auto api = connect_api(o);
    const nlohmann::json rollback = {{"version", version}};
    const ApiAnswer a = version > 0 ? api->request("POST", "/projects/rollback", &rollback)
                                    : api->request("POST", "/projects/reload");
    return print_change_answer(*api, a, version > 0 ? "version " + std::to_string(version) : "the project file",
                               false, kExitTestFailed);
  });
}

}  // namespace syncplc::cli
