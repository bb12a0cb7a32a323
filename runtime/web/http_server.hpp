// HTTP/1.1 (and HTTPS) on Boost.Beast, with every bound of request_limits
// held: the network threads read each request's head and body within their
// limits and deadlines, a worker runs the handler, and the answer (or a
// stream of Server-Sent Events) goes back under a write timeout. Connections
// beyond the limit are refused at once; idle and slow ones are cut.
#pragma once

#include <sched.h>

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "runtime/web/http/message.hpp"
#include "runtime/web/http/request_limits.hpp"

namespace syncplc::web::http {

struct ServerOptions {
  std::string bind = "127.0.0.1";
  int port = 0;                    // 0: any free port
  std::string tls_cert, tls_key;   // both: HTTPS
  Limits limits;
  std::size_t max_connections = 256;  // open at once; more are answered 503 and closed
  std::size_t workers = 72;           // handlers at once (a live stream holds one)
  std::size_t network_threads = 2;
};

// A request read whole and within the limits: answer it (on a worker).
using RequestHandler = std::function<void(Request&, Response&)>;
// A request refused before any handler (a limit, a malformed request): its answer.
using RefusalHandler = std::function<void(const Refusal&, Response&)>;

class HttpServer {
 public:
  HttpServer(ServerOptions options, RequestHandler handle, RefusalHandler refuse);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds, listens and starts the threads; false with `error` when the
  // address cannot be bound or the TLS files do not load.
  bool start(std::string* error);
  // Closes the listener and every connection, runs what workers hold to its
  // end and joins the threads.
  void stop();
  // Moves every thread (network and workers) to `cpus`; "" or why not.
  // From one thread at a time, while started.
  std::string keep_to(const cpu_set_t& cpus);
  int port() const;
  std::size_t connections() const;
  std::size_t refused_connections() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace syncplc::web::http
