// Projects over HTTP (docs/http-api.md): check without loading, load by
// online change, reload the instance's file, roll back to a stored version.
// The change itself is `run`'s main thread's (PlcHost::change), exactly as
// `syncplc reload` asks for it.
#include <thread>

#include "runtime/store/database.hpp"
#include "runtime/store/event_log.hpp"
#include "runtime/store/project_store.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/project_upload.hpp"

namespace syncplc::web {
namespace {

// The project store's number of the version a change made: the newest
// version recorded since `since_ns` with the running program's files. The
// store thread writes it shortly after the change; null when it does not
// appear within two seconds (a store that is off or in FAULT).
nlohmann::json stored_version(ApiContext& c, std::int64_t since_ns) {
  const std::string path = c.host.database_path();
  if (path.empty() || path == store::kMemoryDatabase) return nullptr;
  const std::string hash = c.host.runtime_status().value("project_hash", "");
  for (int i = 0; i < 40; ++i) {
    std::string why;
    if (auto db = store::Database::open_read_only(path, &why); db && db->sql().tableExists("project_versions")) {
      const auto versions = store::list_versions(db->sql());
      for (auto it = versions.rbegin(); it != versions.rend() && it->time_ns >= since_ns; ++it)
        if (it->accepted && it->hash == hash) return it->number;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return nullptr;
}

void answer_change(ApiContext& c, const ChangeOutcome& o, http::Response& res, const std::string& dir,
                   std::int64_t since_ns) {
  nlohmann::json errors = nlohmann::json::array();
  if (!o.accepted)
    for (const auto& l : o.lines) errors.push_back(error_json(l, dir));
  nlohmann::json report = o.report;
  report["summary"] = o.summary;
  nlohmann::json body{{"ok", o.accepted}, {"summary", o.summary}, {"errors", errors}, {"lines", o.lines}};
  if (o.accepted) {
    body["report"] = report;
    body["version"] = stored_version(c, since_ns);
  } else {
    body["error"] = o.summary;
  }
  send_json(res, o.accepted ? 200 : o.status, body);
}

}  // namespace

void add_project_routes(http::Router& s, ApiContext& c) {
  // One handler for check and load: both check first.
  auto upload = [&c](bool load) {
    return [&c, load](const http::Request& req, http::Response& res) {
      auto who = c.need(req, res, Role::Engineer);
      if (!who) return;
      auto body = c.json_body(req, res, c.config.max_upload);
      if (!body) return;
      std::string why;
      auto u = parse_upload(*body, c.config.max_upload_files, &why);
      if (!u) {
        send_error(res, 400, why);
        return;
      }
      const std::string root = c.host.upload_dir();
      const UploadCheck check = check_upload(*u, root, c.host.load_options());
      if (!check.ok) {
        if (load) {
          // A load refused before it reached the PLC: on record as an event.
          std::string text = "upload of " + u->files.front().path + " by " + who->user + " rejected:";
          for (const auto& e : check.errors)
            text += "\n" + (e["where"].is_string() ? e["where"].get<std::string>() + ": " : "") + e["message"].get<std::string>();
          c.host.record_event("reload-failed", "", text, ApiContext::client(req));
        }
        send_json(res, 400, {{"ok", false},
                             {"error", "the project has " + std::to_string(check.errors.size()) + " error" +
                                           (check.errors.size() == 1 ? "" : "s") + "; nothing was changed"},
                             {"errors", check.errors}});
        return;
      }
      if (!load) {
        send_json(res, 200, {{"ok", true}, {"errors", nlohmann::json::array()}, {"hash", check.hash}});
        return;
      }
      const std::string main = keep_upload(*u, root, check.hash, &why);
      if (main.empty()) {
        send_error(res, 500, why);
        return;
      }
      ChangeRequest r;
      r.kind = ChangeRequest::Kind::Load;
      r.project_file = main;
      r.user = who->user;
      r.client = ApiContext::client(req);
      const std::int64_t since = store::wall_now_ns();
      answer_change(c, c.host.change(r), res, root + "/" + check.hash, since);
    };
  };
  s.Post("/api/v1/projects/check", upload(false));
  s.Post("/api/v1/projects/load", upload(true));

  s.Post("/api/v1/projects/reload", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Engineer);
    if (!who) return;
    ChangeRequest r;
    r.kind = ChangeRequest::Kind::Reload;
    r.user = who->user;
    r.client = ApiContext::client(req);
    const std::int64_t since = store::wall_now_ns();
    answer_change(c, c.host.change(r), res, "", since);
  });

  s.Post("/api/v1/projects/rollback", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Engineer);
    if (!who) return;
    auto body = c.json_body(req, res);
    if (!body) return;
    const auto v = body->find("version");
    if (v == body->end() || !v->is_number_integer() || v->get<std::int64_t>() < 1) {
      send_error(res, 400, R"(expected {"version": N}, N a stored version (GET /api/v1/projects))");
      return;
    }
    ChangeRequest r;
    r.kind = ChangeRequest::Kind::Rollback;
    r.version = v->get<std::int64_t>();
    r.user = who->user;
    r.client = ApiContext::client(req);
    const std::int64_t since = store::wall_now_ns();
    answer_change(c, c.host.change(r), res, "", since);
  });
}

}  // namespace syncplc::web
