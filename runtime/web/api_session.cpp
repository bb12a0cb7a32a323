// POST /login, POST /logout, GET /me (docs/http-api.md, "Authentication and roles").
#include <cmath>

#include "runtime/web/api.hpp"

namespace syncplc::web {

void add_session_routes(http::Router& s, ApiContext& c) {
  s.Post("/api/v1/login", [&c](const http::Request& req, http::Response& res) {
    auto body = c.json_body(req, res);
    if (!body) return;
    const auto user = body->find("user"), password = body->find("password");
    if (user == body->end() || !user->is_string() || password == body->end() || !password->is_string()) {
      send_error(res, 400, R"(expected {"user": "name", "password": "..."})");
      return;
    }
    const std::string name = user->get<std::string>(), address = req.remote_addr;
    const std::int64_t now = steady_now_ns();
    if (auto wait = c.limiter.refused_for_ns(address, name, now)) {
      const auto seconds = static_cast<long long>(std::ceil(static_cast<double>(*wait) * 1e-9));
      res.set_header("Retry-After", std::to_string(seconds));
      send_error(res, 429, "too many failed logins from this address or for this name: try again in " + std::to_string(seconds) + " s");
      return;
    }
    // Argon2 takes 64 MiB a hash: logins beyond a few at once wait their turn.
    auto permit = c.hashes.try_acquire();
    if (!permit) {
      send_error(res, 503, "the PLC is checking other logins; try again in a moment");
      return;
    }
    UserStore* users = nullptr;
    std::string why;
    {
      std::lock_guard lock(c.users_mutex);
      users = c.user_store(&why);
    }
    if (!users) {
      send_error(res, 503, why);
      return;
    }
    // Outside any lock of ours: a hash takes a while, other requests go on.
    const std::optional<User> who = users->verify(name, password->get<std::string>());
    const std::string client = ApiContext::client(req);
    if (!who) {
      c.limiter.failed(address, name, now);
      c.counters.logins_failed.fetch_add(1, std::memory_order_relaxed);
      // The name only when it is a user's (login_events.hpp): a password
      // typed into the name field stays out of the log anyone may read.
      bool known = false;
      try {
        known = check_user_name(name).empty() && users->exists(name);
      } catch (const std::exception&) {
        known = false;  // a table that cannot be read names nobody
      }
      c.host.record_event("login-failed", "", failed_login_text(name, known), client);
      send_error(res, 401, "wrong user name or password");
      return;
    }
    c.limiter.succeeded(address, name);
    c.counters.logins.fetch_add(1, std::memory_order_relaxed);
    const std::string token = c.sessions.issue(*who, steady_now_ns());
    // Once per user, role and host within a window (login_events.hpp): the
    // command line's logins do not bury the log.
    if (c.login_events.record_login(who->name, std::string(role_name(who->role)), address, steady_now_ns()))
      c.host.record_event("login", "", who->name + " logged in (" + std::string(role_name(who->role)) + ")", client);
    send_json(res, 200, {{"token", token}, {"user", who->name}, {"role", role_name(who->role)},
                         {"expires_in_s", c.sessions.lifetime_ns() / 1'000'000'000}});
  });

  s.Post("/api/v1/logout", [&c](const http::Request& req, http::Response& res) {
    const std::string h = req.get_header_value("Authorization");
    if (h.rfind("Bearer ", 0) == 0) {
      c.sessions.revoke(h.substr(7));
      c.subscriptions.remove_owner(h.substr(7));  // its live values end with it
    }
    send_json(res, 200, nlohmann::json::object());
  });

  s.Get("/api/v1/me", [&c](const http::Request& req, http::Response& res) {
    auto who = c.session(req);
    if (!who) {
      send_error(res, 401, "not logged in");
      return;
    }
    send_json(res, 200, {{"user", who->user}, {"role", role_name(who->role)}});
  });
}

}  // namespace syncplc::web
