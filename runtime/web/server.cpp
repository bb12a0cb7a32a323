#include "runtime/web/server.hpp"

#include <time.h>

#include <chrono>
#include <thread>

#include "runtime/core/task_cpus.hpp"
#include "runtime/store/database.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/descriptor_budget.hpp"
#include "runtime/web/hmi_location.hpp"
#include "runtime/web/http/router.hpp"
#include "runtime/web/http_server.hpp"
#include "runtime/web/json_values.hpp"
#include "runtime/web/static_files.hpp"

namespace syncplc::web {

std::int64_t steady_now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void send_json(http::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  // Replacement characters for bytes that are not UTF-8 (a tag description
  // read from a file): an answer never fails to encode.
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

void send_error(http::Response& res, int status, const std::string& message, const std::string& where) {
  nlohmann::json j{{"error", message}};
  if (!where.empty()) j["where"] = where;
  send_json(res, status, j);
}

std::string ApiContext::client(const http::Request& req) {
  return req.remote_addr.find(':') != std::string::npos ? "[" + req.remote_addr + "]:" + std::to_string(req.remote_port)
                                                        : req.remote_addr + ":" + std::to_string(req.remote_port);
}

std::optional<Session> ApiContext::session(const http::Request& req) {
  const std::string h = req.get_header_value("Authorization");
  static constexpr std::string_view kBearer = "Bearer ";
  if (h.size() <= kBearer.size() || h.compare(0, kBearer.size(), kBearer) != 0) return std::nullopt;
  return session_of(h.substr(kBearer.size()));
}

std::optional<Session> ApiContext::session_of(const std::string& token) {
  auto s = sessions.check(token, steady_now_ns());
  if (!s) return s;
  // `syncplc user remove`, `passwd` or `role` may have changed the user
  // since the login (another process): the table's stamp decides, at every request.
  UserStore* users = nullptr;
  {
    std::lock_guard lock(users_mutex);
    std::string why;
    users = user_store(&why);
  }
  std::optional<User> now;
  try {
    if (users) now = users->find(s->user);  // UserStore is thread-safe
  } catch (const std::exception&) {
    now.reset();  // a table that cannot be read grants nothing
  }
  if (!now) {
    sessions.revoke_user(s->user);
    return std::nullopt;
  }
  // Only this token: a login after the change has the new stamp and stays.
  if (now->stamp != s->stamp || now->role != s->role) {
    sessions.revoke(token);
    return std::nullopt;
  }
  return s;
}

bool ApiContext::may_read(const http::Request& req, http::Response& res) {
  if (anonymous_reads(config) || session(req)) return true;
  send_error(res, 401, "log in first: this PLC does not allow reads without a login");
  return false;
}

std::optional<Session> ApiContext::need(const http::Request& req, http::Response& res, Role role) {
  auto s = session(req);
  if (!s) {
    send_error(res, 401, "log in first: this changes the PLC");
    return std::nullopt;
  }
  if (!role_allows(s->role, role)) {
    send_error(res, 403, "this needs the " + std::string(role_name(role)) + " role; " + s->user + " is " +
                             std::string(role_name(s->role)));
    return std::nullopt;
  }
  return s;
}

bool ApiContext::with_published_program(const std::function<bool(Program&)>& read) {
  bool complete = false;
  for (int attempt = 0; attempt < 25; ++attempt) {
    host.with_program([&](Program& p) { complete = read(p); });
    if (complete) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(4));
  }
  return complete;
}

std::optional<nlohmann::json> ApiContext::json_body(const http::Request& req, http::Response& res,
                                                    std::size_t max_bytes) {
  if (req.body.size() > (max_bytes ? max_bytes : config.max_body)) {
    send_error(res, 413, "the request body is " + std::to_string(req.body.size()) + " bytes; at most " +
                             std::to_string(max_bytes ? max_bytes : config.max_body) + " are taken here");
    return std::nullopt;
  }
  // Only JSON: a form another site's page could post without asking is refused.
  const std::string type = req.get_header_value("Content-Type");
  if (type.compare(0, 16, "application/json") != 0) {
    send_error(res, 415, "send the body as application/json (Content-Type was '" + type + "')");
    return std::nullopt;
  }
  std::string why;
  auto j = parse_json_body(req.body, &why);  // json_values.hpp: never throws
  if (!j) {
    send_error(res, 400, why);
    return std::nullopt;
  }
  if (!j->is_object()) {
    send_error(res, 400, "the body must be a JSON object");
    return std::nullopt;
  }
  return j;
}

UserStore* ApiContext::user_store(std::string* error) {
  if (users) return users.get();
  const std::string path = host.database_path();
  if (path.empty() || path == store::kMemoryDatabase) {
    *error = "this PLC keeps no database (--db :memory:), so it has no users: nobody can log in";
    return nullptr;
  }
  users = UserStore::open(path, error);
  return users.get();
}

bool ApiContext::wait_ns(std::int64_t ns) {
  std::unique_lock lock(stop_mutex);
  return !stop_cv.wait_for(lock, std::chrono::nanoseconds(ns), [&] { return stopping.load(); });
}

namespace {

const char* kContentSecurityPolicy =
    "default-src 'self'; frame-ancestors 'none'; form-action 'none'; base-uri 'none'";

// A Host header this server may answer to: while it listens on loopback,
// only loopback names, so a page of another site whose name resolves to
// 127.0.0.1 (DNS rebinding) cannot talk to it.
bool host_allowed(const WebConfig& c, const std::string& host) {
  if (!is_loopback(c.bind)) return true;
  std::string name = host;
  if (!name.empty() && name.front() == '[') name = name.substr(0, name.find(']') + 1);
  else if (const auto colon = name.rfind(':'); colon != std::string::npos) name = name.substr(0, colon);
  return name == "localhost" || name == "[::1]" || is_loopback(name);
}

// On every answer, a refusal's too.
void security_headers(http::Response& res) {
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("X-Frame-Options", "DENY");
}

}  // namespace

struct Server::Impl {
  Impl(WebConfig c, PlcHost& h) : config(std::move(c)), context(config, h, counters) {}
  WebConfig config;
  ServerCounters counters;
  ApiContext context;
  http::Router router;
  StaticFiles files;
  std::string no_hmi;  // why "/" has no HMI, when it has none
  std::unique_ptr<http::HttpServer> beast;
  std::size_t connection_limit = 0;
  int port = 0;

  void handle(http::Request& req, http::Response& res);
  void route(http::Request& req, http::Response& res);
};

void Server::Impl::handle(http::Request& req, http::Response& res) {
  counters.requests.fetch_add(1, std::memory_order_relaxed);
  try {
    route(req, res);
  } catch (const std::exception& e) {
    res = http::Response();
    send_error(res, 500, std::string("internal error: ") + e.what());
  }
  security_headers(res);
  if (res.status >= 400) counters.refused.fetch_add(1, std::memory_order_relaxed);
}

void Server::Impl::route(http::Request& req, http::Response& res) {
  if (!host_allowed(config, req.get_header_value("Host"))) {
    send_error(res, 403, "this PLC answers only to the names of this machine (Host '" + req.get_header_value("Host") + "')");
    return;
  }
  // A request another site's page sends: never acted on.
  const std::string origin = req.get_header_value("Origin");
  if (!origin.empty() && req.method != "GET" && req.method != "HEAD") {
    const std::string host = req.get_header_value("Host");
    if (origin != "http://" + host && origin != "https://" + host) {
      send_error(res, 403, "a request from another site (Origin " + origin + ") is refused");
      return;
    }
  }
  if (router.dispatch(req, res) == http::Router::Outcome::Handled) return;
  const bool read = req.method == "GET" || req.method == "HEAD";
  if (req.path.rfind("/api/", 0) == 0) {
    send_error(res, 404, "no resource " + req.method + " " + req.path);
  } else if (read && files.serve(req.path, res)) {
    // The HMI, under the strictest content security policy it is built for.
    res.set_header("Content-Security-Policy", kContentSecurityPolicy);
    res.set_header("Cache-Control", "no-cache");
  } else if (read && req.path == "/" && !no_hmi.empty()) {
    res.status = 404;
    res.set_content(no_hmi + "\n", "text/plain");
  } else {
    send_error(res, 404, "not found: " + req.path);
  }
}

Server::Server(WebConfig config, PlcHost& host) : impl_(std::make_unique<Impl>(std::move(config), host)) {}

Server::~Server() { stop(); }

bool Server::start(std::string* error) {
  const WebConfig& c = impl_->config;
  if (!check_config(c, error)) return false;
  Impl& impl = *impl_;
  ApiContext& ctx = impl.context;
  add_session_routes(impl.router, ctx);
  add_read_routes(impl.router, ctx);
  add_change_routes(impl.router, ctx);
  add_project_routes(impl.router, ctx);
  add_stream_routes(impl.router, ctx);
  add_axis_routes(impl.router, ctx);

  const std::string dist = c.hmi_dir.empty() ? default_hmi_dir() : c.hmi_dir;
  if (!impl.files.open(dist))
    impl.no_hmi = "The HMI is not built here (no " + dist + "/index.html): run scripts/build_hmi.sh. The API is at /api/v1.";

  http::ServerOptions o;
  o.bind = c.bind;
  o.port = c.port;
  o.tls_cert = c.tls_cert;
  o.tls_key = c.tls_key;
  o.limits.max_body = c.max_body;
  o.limits.max_upload_body = c.max_upload + 64 * 1024;  // the JSON around the files
  // Every descriptor this process may have, and of them only a share for
  // HTTP connections: the Modbus server and the drivers keep the rest.
  impl.connection_limit = http_connection_budget(c.max_connections, raise_descriptor_limit());
  o.max_connections = impl.connection_limit;
  // One worker per live stream and a few for everything else: a stream
  // holds its worker; other requests wait for one, their connections
  // counted against the limit.
  o.workers = c.max_streams + 8;
  impl.beast = std::make_unique<http::HttpServer>(
      o, [&impl](http::Request& req, http::Response& res) { impl.handle(req, res); },
      [&impl](const http::Refusal& r, http::Response& res) {
        impl.counters.requests.fetch_add(1, std::memory_order_relaxed);
        impl.counters.refused.fetch_add(1, std::memory_order_relaxed);
        send_error(res, r.status, r.message);
        security_headers(res);
      });
  std::string why;
  if (!impl.beast->start(&why)) {
    if (why.rfind("HTTPS:", 0) == 0) *error = why;
    else if (c.port == 0) *error = "the HTTP server cannot listen on " + c.bind + " (any port): " + why;
    else
      *error = "the HTTP server cannot listen on " + c.bind + ":" + std::to_string(c.port) + " (" + why +
               "; in use? --http ADDR:PORT chooses another, --http off turns it off)";
    impl.beast.reset();
    return false;
  }
  impl.port = impl.beast->port();
  if (!c.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int cpu : c.cpus) CPU_SET(cpu, &set);  // within the process's CPUs (check_config)
    if (const std::string failed = impl.beast->keep_to(set); !failed.empty()) {
      *error = "cannot keep the HTTP server's threads to CPU " + cpu_list(set) + ": " + failed;
      impl.beast->stop();
      impl.beast.reset();
      return false;
    }
  }
  return true;
}

void Server::stop() {
  if (!impl_->beast) return;
  {
    std::lock_guard lock(impl_->context.stop_mutex);
    impl_->context.stopping.store(true);
  }
  impl_->context.stop_cv.notify_all();
  impl_->beast->stop();
  impl_->beast.reset();
}

std::string Server::url() const {
  const std::string& b = impl_->config.bind;
  const std::string host = b.find(':') != std::string::npos ? "[" + b + "]" : b;
  return std::string(impl_->config.tls() ? "https://" : "http://") + host + ":" + std::to_string(port()) + "/";
}

int Server::port() const { return impl_->port; }

std::size_t Server::connection_limit() const { return impl_->connection_limit; }

const ServerCounters& Server::counters() const { return impl_->counters; }

std::string Server::keep_to(const cpu_set_t& cpus) { return impl_->beast ? impl_->beast->keep_to(cpus) : std::string(); }

}  // namespace syncplc::web
