// What the API's handler files share (runtime/web only): the caller's
// session, the checks every request goes through, and JSON answers.
// Each api_*.cpp adds one group of routes (docs/http-api.md).
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "runtime/web/http/message.hpp"
#include "runtime/web/login_events.hpp"
#include "runtime/web/plc_host.hpp"
#include "runtime/web/read_access.hpp"
#include "runtime/web/roles.hpp"
#include "runtime/web/http/router.hpp"
#include "runtime/web/server.hpp"
#include "runtime/web/sessions.hpp"
#include "runtime/web/subscriptions.hpp"
#include "runtime/web/users.hpp"
#include "runtime/web/web_config.hpp"

namespace syncplc::web {

std::int64_t steady_now_ns();

struct ApiContext {
  ApiContext(const WebConfig& c, PlcHost& h, ServerCounters& n) : config(c), host(h), counters(n) {}

  const WebConfig& config;
  PlcHost& host;
  ServerCounters& counters;
  Sessions sessions;
  LoginLimiter limiter;
  LoginEvents login_events;
  HashGate hashes;
  HiddenCellsCache hidden_cells;  // what only engineers see (read_access.hpp)
  Subscriptions subscriptions;    // live values (subscriptions.hpp)
  // The users' table, opened at the first login (its own connection to the
  // PLC's database; thread-safe). The mutex guards only the opening.
  std::mutex users_mutex;
  std::unique_ptr<UserStore> users;

  // stop(): live streams end at their next tick.
  std::atomic<bool> stopping{false};
  std::mutex stop_mutex;
  std::condition_variable stop_cv;
  std::atomic<std::size_t> streams{0};

  // The caller's session from `Authorization: Bearer TOKEN`; nullopt without one.
  std::optional<Session> session(const http::Request& req);
  // The same for a token, checked against the users table (a removed user
  // or a changed role ends the session).
  std::optional<Session> session_of(const std::string& token);
  // A read: allowed anonymously when the settings say so, else with any
  // session. Answers 401 itself and returns false otherwise.
  bool may_read(const http::Request& req, http::Response& res);
  // A change: the session when its role allows `need`; 401 or 403 answered otherwise.
  std::optional<Session> need(const http::Request& req, http::Response& res, Role need);
  // The body as a JSON object (400, 413, 415 answered otherwise).
  std::optional<nlohmann::json> json_body(const http::Request& req, http::Response& res,
                                          std::size_t max_bytes = 0);
  // The users' table, opened on first use; null with `error` when the PLC
  // keeps no database (--db :memory:) or it cannot be opened.
  UserStore* user_store(std::string* error);
  // "ip:port" of the client.
  static std::string client(const http::Request& req);
  // Sleeps up to ns; false when the server stops meanwhile.
  bool wait_ns(std::int64_t ns);
  // Runs `read` with the program held until it returns true: false means a
  // pin it read had no copy yet (nobody watched it before; the task
  // publishes one at its next scan, pin_monitor.hpp). Asks again 4 ms later
  // without holding the program meanwhile, at most 25 times; returns the
  // last answer.
  bool with_published_program(const std::function<bool(Program&)>& read);
};

void send_json(http::Response& res, int status, const nlohmann::json& body);
void send_error(http::Response& res, int status, const std::string& message, const std::string& where = "");

void add_session_routes(http::Router& s, ApiContext& c);
void add_read_routes(http::Router& s, ApiContext& c);
void add_change_routes(http::Router& s, ApiContext& c);
void add_project_routes(http::Router& s, ApiContext& c);
void add_stream_routes(http::Router& s, ApiContext& c);
void add_axis_routes(http::Router& s, ApiContext& c);  // api_axes.cpp

}  // namespace syncplc::web
