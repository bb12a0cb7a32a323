#include "runtime/web/server.hpp"

#include <httplib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>

#include <functional>
#include <thread>

#include "runtime/store/database.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/json_values.hpp"
#include "runtime/web/worker_pool.hpp"

namespace syncplc::web {

std::int64_t steady_now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void send_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");
  // Replacement characters for bytes that are not UTF-8 (a tag description
  // read from a file): an answer never fails to encode.
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& message, const std::string& where) {
  nlohmann::json j{{"error", message}};
  if (!where.empty()) j["where"] = where;
  send_json(res, status, j);
}

std::string ApiContext::client(const httplib::Request& req) {
  return req.remote_addr.find(':') != std::string::npos ? "[" + req.remote_addr + "]:" + std::to_string(req.remote_port)
                                                        : req.remote_addr + ":" + std::to_string(req.remote_port);
}

std::optional<Session> ApiContext::session(const httplib::Request& req) {
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

bool ApiContext::may_read(const httplib::Request& req, httplib::Response& res) {
  if (anonymous_reads(config) || session(req)) return true;
  send_error(res, 401, "log in first: this PLC does not allow reads without a login");
  return false;
}

std::optional<Session> ApiContext::need(const httplib::Request& req, httplib::Response& res, Role role) {
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

std::optional<nlohmann::json> ApiContext::json_body(const httplib::Request& req, httplib::Response& res,
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

// cpp-httplib 0.11 listens with a backlog of 5 (compiled into Debian's
// library): HMI pages that all reconnect at once (after a restart) would
// have their SYNs dropped and wait seconds for TCP's retries. listen()
// again on the bound socket widens the queue (docs/benchmarks.md §12).
constexpr int kListenBacklog = 128;
template <class S>
struct WideBacklog : S {
  using S::S;
  void widen() { ::listen(this->svr_sock_, kListenBacklog); }
};

}  // namespace

struct Server::Impl {
  Impl(WebConfig c, PlcHost& h) : config(std::move(c)), context(config, h, counters) {}
  WebConfig config;
  ServerCounters counters;
  ApiContext context;
  std::unique_ptr<httplib::Server> http;
  std::thread listener;
  int port = 0;
};

Server::Server(WebConfig config, PlcHost& host) : impl_(std::make_unique<Impl>(std::move(config), host)) {}

Server::~Server() { stop(); }

bool Server::start(std::string* error) {
  const WebConfig& c = impl_->config;
  if (!check_config(c, error)) return false;
  std::function<void()> widen_backlog;
  if (c.tls()) {
    auto tls = std::make_unique<WideBacklog<httplib::SSLServer>>(c.tls_cert.c_str(), c.tls_key.c_str());
    if (!tls->is_valid()) {
      *error = "HTTPS: cannot load the certificate " + c.tls_cert + " with the key " + c.tls_key;
      return false;
    }
    widen_backlog = [p = tls.get()] { p->widen(); };
    impl_->http = std::move(tls);
  } else {
    auto plain = std::make_unique<WideBacklog<httplib::Server>>();
    widen_backlog = [p = plain.get()] { p->widen(); };
    impl_->http = std::move(plain);
  }
  httplib::Server& s = *impl_->http;
  ApiContext& ctx = impl_->context;
  // One worker per live stream and a few for everything else: a stream
  // holds its worker, and a full pool only queues further connections.
  const std::size_t workers = c.max_streams + 8;
  s.new_task_queue = [workers] { return new WorkerPool(workers); };
  s.set_read_timeout(5, 0);   // a client whose request stalls for 5 s is cut
  s.set_write_timeout(5, 0);  // one that does not read its answer too
  s.set_keep_alive_timeout(2);  // an idle connection gives its worker back soon
  s.set_keep_alive_max_count(100);
  s.set_payload_max_length(c.max_upload + 64 * 1024);
  s.set_tcp_nodelay(true);
  s.set_default_headers({{"X-Content-Type-Options", "nosniff"},
                         {"Referrer-Policy", "no-referrer"},
                         {"X-Frame-Options", "DENY"}});
  s.set_pre_routing_handler([&ctx](const httplib::Request& req, httplib::Response& res) {
    ctx.counters.requests.fetch_add(1, std::memory_order_relaxed);
    if (!host_allowed(ctx.config, req.get_header_value("Host"))) {
      send_error(res, 403, "this PLC answers only to the names of this machine (Host '" +
                               req.get_header_value("Host") + "')");
      return httplib::Server::HandlerResponse::Handled;
    }
    // A request another site's page sends: never acted on.
    const std::string origin = req.get_header_value("Origin");
    if (!origin.empty() && req.method != "GET" && req.method != "HEAD") {
      const std::string host = req.get_header_value("Host");
      if (origin != "http://" + host && origin != "https://" + host) {
        send_error(res, 403, "a request from another site (Origin " + origin + ") is refused");
        return httplib::Server::HandlerResponse::Handled;
      }
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  s.set_post_routing_handler([&ctx](const httplib::Request&, httplib::Response& res) {
    if (res.status >= 400) ctx.counters.refused.fetch_add(1, std::memory_order_relaxed);
  });
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;  // a handler's own answer
    if (res.status == 404 && req.path.rfind("/api/", 0) == 0) send_error(res, 404, "no resource " + req.method + " " + req.path);
    else if (res.status == 413) send_error(res, 413, "the request is larger than this PLC accepts");
    else if (res.status == 400) send_error(res, 400, "malformed HTTP request");
    else if (res.status == 404) send_error(res, 404, "not found: " + req.path);
  });
  s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "internal error";
    try {
      std::rethrow_exception(ep);
    } catch (const std::exception& e) {
      what += std::string(": ") + e.what();
    } catch (...) {
    }
    send_error(res, 500, what);
  });

  add_session_routes(s, ctx);
  add_read_routes(s, ctx);
  add_change_routes(s, ctx);
  add_project_routes(s, ctx);
  add_stream_routes(s, ctx);

  // The HMI: hmi_web/dist, under the strictest content security policy it is built for.
  const std::string dist = c.hmi_dir.empty() ? SYNCPLC_HMI_DIST : c.hmi_dir;
  struct stat st;
  if (stat((dist + "/index.html").c_str(), &st) == 0) {
    s.set_mount_point("/", dist, {{"Content-Security-Policy", kContentSecurityPolicy}, {"Cache-Control", "no-cache"}});
    s.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");
    s.set_file_extension_and_mimetype_mapping("map", "application/json");
  } else {
    const std::string why = "The HMI is not built here (no " + dist + "/index.html): run scripts/build_hmi.sh. The API is at /api/v1.";
    s.Get("/", [why](const httplib::Request&, httplib::Response& res) {
      res.status = 404;
      res.set_content(why + "\n", "text/plain");
    });
  }

  if (c.port == 0) {
    impl_->port = s.bind_to_any_port(c.bind);
    if (impl_->port <= 0) {
      *error = "the HTTP server cannot listen on " + c.bind + " (any port)";
      return false;
    }
  } else {
    if (!s.bind_to_port(c.bind, c.port)) {
      *error = "the HTTP server cannot listen on " + c.bind + ":" + std::to_string(c.port) +
               " (in use? --http ADDR:PORT chooses another, --http off turns it off)";
      return false;
    }
    impl_->port = c.port;
  }
  widen_backlog();
  impl_->listener = std::thread([&s] { s.listen_after_bind(); });
  // stop() ends only a server that runs: wait until it does.
  while (!s.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return true;
}

void Server::stop() {
  if (!impl_->http) return;
  {
    std::lock_guard lock(impl_->context.stop_mutex);
    impl_->context.stopping.store(true);
  }
  impl_->context.stop_cv.notify_all();
  impl_->http->stop();
  if (impl_->listener.joinable()) impl_->listener.join();
  impl_->http.reset();
}

std::string Server::url() const {
  const std::string& b = impl_->config.bind;
  const std::string host = b.find(':') != std::string::npos ? "[" + b + "]" : b;
  return std::string(impl_->config.tls() ? "https://" : "http://") + host + ":" + std::to_string(impl_->port) + "/";
}

int Server::port() const { return impl_->port; }

const ServerCounters& Server::counters() const { return impl_->counters; }

}  // namespace syncplc::web
