// The HTTP server of `syncplc run` (docs/http-api.md): the API under
// /api/v1 and the HMI's files (hmi_web/dist), on Boost.Beast
// (runtime/web/http_server) with the limits of runtime/web/request_limits. It never touches a task: it reads the published snapshots and
// pin monitors, and writes, forces and loads through the PlcHost, which
// uses the tasks' queues and the online change as Modbus and
// `syncplc reload` do.
#pragma once

#include <sched.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "runtime/web/plc_host.hpp"
#include "runtime/web/web_config.hpp"

namespace syncplc::web {

struct ServerCounters {
  std::atomic<std::uint64_t> requests{0};
  std::atomic<std::uint64_t> refused{0};       // 4xx/5xx answers
  std::atomic<std::uint64_t> logins{0};
  std::atomic<std::uint64_t> logins_failed{0};
  std::atomic<std::uint64_t> streams_open{0};
  std::atomic<std::uint64_t> stream_events{0};
};

class Server {
 public:
  Server(WebConfig config, PlcHost& host);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts the worker threads. False with `error` when the
  // address cannot be bound or the TLS files do not load.
  bool start(std::string* error);
  // Ends every live stream and joins the threads.
  void stop();
  // "http://127.0.0.1:8080/"
  std::string url() const;
  int port() const;
  // The HTTP connections it holds at most (WebConfig::max_connections
  // within its share of the file descriptors).
  std::size_t connection_limit() const;
  const ServerCounters& counters() const;
  // Moves every thread of the server to `cpus` (runtime/core/task_cpus.hpp);
  // "" or why not. From one thread at a time, while started.
  std::string keep_to(const cpu_set_t& cpus);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace syncplc::web
