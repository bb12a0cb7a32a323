// The Modbus TCP server of `syncplc run` (issue 5, docs/modbus.md): one
// non-real-time thread that serves every client of the project's tags.
//
// libmodbus 3.1.6 gives the listening socket (modbus_tcp_listen) and builds
// and sends every reply (modbus_reply, modbus_reply_exception; see
// request_handler.hpp). Its receive side is not used: modbus_receive waits
// with select() on one connection for a byte timeout, so one client sending
// half a frame would hold up all others, and select() over an fd_set breaks
// at descriptors >= 1024. Instead one epoll loop reads whatever each
// connection has, non-blocking, into that connection's buffer and answers
// each whole frame as soon as it is in (frame.hpp). Nobody waits for anybody:
// a half frame stays in its buffer, a client that stops reading loses its
// connection when its socket's send buffer is full (a reply never goes out
// in pieces), and a connection without a whole request for idle_timeout is
// closed.
//
// The scan never waits for this thread: reads take a task's published
// snapshot under the task's snapshot lock (never taken by the scan), writes
// go through the task's queue (Task::enqueue).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "runtime/modbus/modbus_config.hpp"
#include "runtime/core/program.hpp"
#include "runtime/modbus/audit.hpp"
#include "runtime/modbus/counters.hpp"
#include "runtime/modbus/request_handler.hpp"

namespace syncplc::modbus {

class Server {
 public:
  Server(Program& program, ModbusSettings settings);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts the thread. False, with the reason, when the address
  // cannot be bound (in use, not an address of this host, ...).
  bool start(std::string* error);
  void stop();
  int port() const { return port_; }          // the bound port (useful with port 0)
  std::string endpoint() const;               // "127.0.0.1:5020"
  const ModbusConfig& config() const { return config_; }
  const Counters& counters() const { return counters_; }
  // Set by start() when the server runs with less than it was configured for
  // (too few descriptors for max_clients); empty otherwise.
  const std::string& warning() const { return warning_; }
  // True when the server thread was kept off the CPUs of pinned tasks
  // (no `cpus` setting, and a CPU without a pinned task was left).
  bool off_task_cpus() const { return off_task_cpus_; }
  // The audit trail (audit.hpp): acknowledged writes and refused
  // connections. Before start(); null: none.
  void set_audit(ServerAudit* audit) {
    audit_ = audit;
    handler_->set_audit(audit);
  }
  // The store status block's source (store_status_source.hpp). Before
  // start(); null: the block reads as "off".
  void set_store_status(const StoreStatusSource* source) { handler_->set_store_status(source); }
  // Coils, inputs and registers mapped (values, not registers).
  std::size_t handler_map_size() const;

  // Online change, in two steps. hold(): returns once the server thread has
  // stopped taking requests (clients wait, their requests stay queued in the
  // kernel). replace_program(): serves `program` from now on, held or not;
  // returns once the thread has let go of the previous one. Write and reads
  // (FC 23) still waiting for the previous program's scans then wait for two
  // publications of the same task of the new program, which the old task
  // makes until its switch (program_change.hpp: it applies the queues and
  // mirrors its publications).
  void hold();
  void replace_program(Program& program, ModbusPlaces places);

 private:
  struct Connection;
  void loop();
  void accept_clients(std::int64_t now);
  void on_readable(std::size_t slot, std::int64_t now);
  void serve_frames(std::size_t slot, std::int64_t now);
  void finish_deferred(std::int64_t now);
  void close_idle(std::int64_t now);
  void close_connection(std::size_t slot, std::atomic<std::uint64_t>& reason);
  void watch(int fd, std::uint64_t key, std::uint32_t events, bool add);
  void hold_and_take_new_program();
  void keep_off_task_cpus();

  Program* program_;
  ModbusConfig config_;
  Counters counters_;
  std::unique_ptr<RequestHandler> handler_;
  ServerAudit* audit_ = nullptr;
  int listen_fd_ = -1;
  int epoll_fd_ = -1;
  int wake_fd_ = -1;  // eventfd: stop and program replacement
  int port_ = 0;
  std::vector<std::unique_ptr<Connection>> slots_;  // max_clients entries; fd -1 when free
  std::vector<std::size_t> deferred_;               // slots with an FC 23 waiting
  std::size_t open_ = 0;
  std::int64_t accept_paused_until_ = 0;            // out of descriptors: retry later
  std::int64_t next_idle_check_ = 0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::mutex swap_mutex_;
  std::condition_variable swap_cv_;
  Program* next_program_ = nullptr;           // under swap_mutex_
  ModbusPlaces next_places_;                  // under swap_mutex_
  std::atomic<bool> hold_requested_{false};
  bool held_ = false;                           // under swap_mutex_: the thread is parked
  bool running_ = false;
  std::string warning_;
  bool off_task_cpus_ = false;
};

}  // namespace syncplc::modbus
