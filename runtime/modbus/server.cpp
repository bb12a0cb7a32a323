#include "runtime/modbus/server.hpp"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <sched.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/task_cpus.hpp"

namespace syncplc::modbus {
namespace {

constexpr std::uint64_t kListenKey = 0;
constexpr std::uint64_t kWakeKey = ~std::uint64_t{0};
// Per connection: room for many pipelined requests, so one recv() serves a burst.
constexpr std::size_t kBufferSize = 4096;
constexpr std::int64_t kIdleCheckNs = 100'000'000;

// Enough descriptors for every client: Debian's soft limit is 1024. Returns
// a warning when the hard limit leaves fewer (accept() then fails with
// EMFILE before max_clients and the server pauses accepting for a moment).
std::string raise_descriptor_limit(int clients) {
  rlimit r{};
  if (getrlimit(RLIMIT_NOFILE, &r) != 0) return {};
  const rlim_t want = static_cast<rlim_t>(clients) + 256;
  if (r.rlim_cur >= want) return {};
  r.rlim_cur = std::min(want, r.rlim_max);
  if (setrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur >= want) return {};
  getrlimit(RLIMIT_NOFILE, &r);
  return "max_clients " + std::to_string(clients) + " needs " + std::to_string(want) +
         " descriptors, this process may open only " + std::to_string(r.rlim_cur) +
         " (raise the hard limit: ulimit -Hn, LimitNOFILE=)";
}

}  // namespace

struct Server::Connection {
  int fd = -1;
  std::uint32_t peer = 0;  // IPv4, host byte order
  std::uint16_t peer_port = 0;
  std::size_t used = 0;    // bytes in buf
  std::int64_t last_request_ns = 0;
  bool paused = false;     // an FC 23 reply is waiting: later frames wait behind it
  PendingReply pending;
  std::uint8_t buf[kBufferSize];
};

Server::Server(Program& program, ModbusSettings settings) : program_(&program), config_(std::move(settings.server)) {
  handler_ = std::make_unique<RequestHandler>(config_, counters_);
  handler_->set_program(program, settings.places);
}

Server::~Server() { stop(); }

std::size_t Server::handler_map_size() const {
  std::size_t n = 0;
  for (int t = 0; t < 4; ++t)
    for (const auto& pt : handler_->map().points(static_cast<ModbusTable>(t)))
      if (pt.status == ModbusPoint::Status::None) ++n;  // tag values; the task status block is said apart
  return n;
}

std::string Server::endpoint() const { return config_.bind + ":" + std::to_string(port_); }

bool Server::start(std::string* error) {
  warning_ = raise_descriptor_limit(config_.max_clients);
  modbus_t* ctx = modbus_new_tcp(config_.bind.c_str(), config_.port);
  if (!ctx) {
    *error = std::string("cannot create the listening context: ") + modbus_strerror(errno);
    return false;
  }
  // modbus_tcp_listen binds with SO_REUSEADDR and listens; the context is only needed for that.
  listen_fd_ = modbus_tcp_listen(ctx, 128);
  const int listen_errno = errno;
  modbus_free(ctx);
  if (listen_fd_ < 0) {
    *error = "cannot listen on " + config_.bind + ":" + std::to_string(config_.port) + ": " + std::strerror(listen_errno);
    return false;
  }
  fcntl(listen_fd_, F_SETFL, fcntl(listen_fd_, F_GETFL) | O_NONBLOCK);
  fcntl(listen_fd_, F_SETFD, FD_CLOEXEC);
  sockaddr_in a{};
  socklen_t len = sizeof a;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
  port_ = ntohs(a.sin_port);

  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  wake_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (epoll_fd_ < 0 || wake_fd_ < 0) {
    *error = std::string("epoll/eventfd: ") + std::strerror(errno);
    stop();
    return false;
  }
  watch(listen_fd_, kListenKey, EPOLLIN, true);
  watch(wake_fd_, kWakeKey, EPOLLIN, true);
  slots_.clear();
  for (int i = 0; i < config_.max_clients; ++i) slots_.push_back(std::make_unique<Connection>());
  deferred_.reserve(slots_.size());
  stop_.store(false);
  running_ = true;
  thread_ = std::thread([this] { loop(); });
  pthread_setname_np(thread_.native_handle(), "modbus");  // as ps -L and top -H show it; task threads carry their task's name
  if (!config_.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (int cpu : config_.cpus) CPU_SET(cpu, &set);
    if (const int rc = pthread_setaffinity_np(thread_.native_handle(), sizeof set, &set); rc != 0) {
      std::string list;
      for (int cpu : config_.cpus) list += (list.empty() ? "" : ",") + std::to_string(cpu);
      *error = "cannot keep the server thread to CPU " + list + ": " + std::strerror(rc);
      stop();
      return false;
    }
  } else {
    keep_off_task_cpus();
  }
  return true;
}

// Without `cpus`, the server thread keeps off the CPUs the project pins its
// real-time tasks to (task `cpu:`), as long as another CPU is left
// (runtime/core/task_cpus.hpp, the rule every thread that is not real-time
// follows). Nothing pinned: any CPU the process may use.
void Server::keep_off_task_cpus() {
  const TaskCpuChoice choice = cpus_off_tasks(process_cpus(), pinned_cpus(*program_));
  if (!choice.off && !off_task_cpus_) return;  // nothing pinned, nothing to undo
  off_task_cpus_ = choice.off;
  if (const std::string why = keep_thread_to(thread_.native_handle(), choice.cpus); !why.empty())
    warning_ += (warning_.empty() ? "" : "; ") + std::string("cannot keep the server thread off the tasks' CPUs: ") + why;
}

void Server::stop() {
  if (thread_.joinable()) {
    {
      std::lock_guard lk(swap_mutex_);  // a thread held for an online change waits on swap_cv_
      stop_.store(true, std::memory_order_release);
    }
    swap_cv_.notify_all();
    const std::uint64_t one = 1;
    if (write(wake_fd_, &one, sizeof one) < 0) { /* the loop also polls stop_ every 100 ms */ }
    thread_.join();
  }
  {
    std::lock_guard lk(swap_mutex_);
    running_ = false;
  }
  swap_cv_.notify_all();
  // Connections still open at shutdown are closed without counting them as
  // closed by anyone: the counters say what happened while serving.
  for (auto& c : slots_)
    if (c->fd >= 0) {
      close(c->fd);
      c->fd = -1;
    }
  for (int* fd : {&listen_fd_, &epoll_fd_, &wake_fd_})
    if (*fd >= 0) { close(*fd); *fd = -1; }
}

void Server::hold() {
  std::unique_lock lk(swap_mutex_);
  if (!running_ || held_) return;
  hold_requested_.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  if (write(wake_fd_, &one, sizeof one) < 0) { /* polled every 100 ms as well */ }
  swap_cv_.wait(lk, [this] { return held_ || !running_ || stop_.load(); });
}

void Server::replace_program(Program& program, ModbusPlaces places) {
  std::unique_lock lk(swap_mutex_);
  if (!running_) {
    program_ = &program;
    handler_->set_program(program, places);
    return;
  }
  next_program_ = &program;
  next_places_ = std::move(places);
  if (!held_) {
    hold_requested_.store(true, std::memory_order_release);
    const std::uint64_t one = 1;
    if (write(wake_fd_, &one, sizeof one) < 0) { /* polled every 100 ms as well */ }
  }
  swap_cv_.notify_all();
  swap_cv_.wait(lk, [this] { return next_program_ == nullptr || !running_ || stop_.load(); });
}

// In the server thread: parks until replace_program() (or stop()) gives the
// next program, then serves it. Clients wait meanwhile: their requests stay
// in the kernel's buffers, nothing is read, answered or lost.
void Server::hold_and_take_new_program() {
  std::unique_lock lk(swap_mutex_);
  held_ = true;
  swap_cv_.notify_all();
  swap_cv_.wait(lk, [this] { return next_program_ != nullptr || stop_.load(); });
  held_ = false;
  hold_requested_.store(false, std::memory_order_release);
  if (!next_program_) return;  // stopping
  const std::int64_t now = monotonic_ns();
  Program* old = program_;
  program_ = next_program_;
  handler_->set_program(*program_, next_places_);
  if (config_.cpus.empty()) keep_off_task_cpus();  // the new program may pin its tasks elsewhere
  // Write-and-reads that wait for the old program's scans now wait for the
  // same tasks of the new one: from the online change on, the old tasks apply
  // the new program's queues too and their publications count as the new
  // tasks' (program_change.hpp), so two more publications of the new task
  // hold every write queued before. A task the new program lacks cannot
  // publish it: that request is answered from the new program at once.
  std::vector<std::size_t> waiting;
  waiting.swap(deferred_);
  for (std::size_t slot : waiting) {
    Connection& c = *slots_[slot];
    if (c.fd < 0) continue;
    bool rearmed = true;
    for (auto& w : c.pending.waits) {
      const int t = program_->find_task(old->tasks[w.task]->config().name);
      if (t < 0) { rearmed = false; break; }
      w.task = static_cast<std::uint16_t>(t);
      w.published = program_->tasks[w.task]->published_count() + 2;
    }
    if (rearmed) {
      // The change itself may take up to three periods of the slowest task.
      std::int64_t longest = 0;
      for (const auto& t : program_->tasks) longest = std::max(longest, t->config().period_ns);
      c.pending.deadline_ns = std::max(c.pending.deadline_ns, now + 3 * longest + deferral_limit_ns(*program_, c.pending.waits));
      deferred_.push_back(slot);
      continue;
    }
    if (handler_->answer_now(c.fd, c.pending) != RequestHandler::Outcome::Sent) {
      close_connection(slot, counters_.closed_unsendable);
      continue;
    }
    c.paused = false;
    watch(c.fd, slot + 1, EPOLLIN | EPOLLRDHUP, false);
    serve_frames(slot, now);
  }
  next_program_ = nullptr;
  swap_cv_.notify_all();
}

void Server::watch(int fd, std::uint64_t key, std::uint32_t events, bool add) {
  epoll_event ev{};
  ev.events = events;
  ev.data.u64 = key;
  epoll_ctl(epoll_fd_, add ? EPOLL_CTL_ADD : EPOLL_CTL_MOD, fd, &ev);
}

void Server::loop() {
  epoll_event events[64];
  while (!stop_.load(std::memory_order_acquire)) {
    // 1 ms while an FC 23 waits for its scan; otherwise wake for idle checks only.
    const int timeout_ms = deferred_.empty() ? static_cast<int>(kIdleCheckNs / 1'000'000) : 1;
    const int n = epoll_wait(epoll_fd_, events, 64, timeout_ms);
    const std::int64_t now = monotonic_ns();
    if (hold_requested_.load(std::memory_order_acquire)) {
      hold_and_take_new_program();
      continue;  // the events of this round may be of connections closed meanwhile: wait again
    }
    for (int i = 0; i < n; ++i) {
      const std::uint64_t key = events[i].data.u64;
      if (key == kWakeKey) {
        std::uint64_t v;
        while (read(wake_fd_, &v, sizeof v) > 0) {}
      } else if (key == kListenKey) {
        accept_clients(now);
      } else {
        const std::size_t slot = key - 1;
        if (slot >= slots_.size() || slots_[slot]->fd < 0) continue;
        if (slots_[slot]->paused) {
          if (events[i].events & (EPOLLHUP | EPOLLERR)) {
            // Reset, or both directions shut, while its FC 23 waits: nobody
            // can read the reply. (epoll reports these whatever the mask, so
            // the connection must go, or the loop would spin.)
            close_connection(slot, counters_.closed_by_peer);
            continue;
          }
          // The client shut its sending side while its FC 23 waits: stop
          // watching (level-triggered, this would spin); the reply is still
          // sent, and the next read finds the end of the stream.
          watch(slots_[slot]->fd, key, 0, false);
          continue;
        }
        on_readable(slot, now);
      }
    }
    if (!deferred_.empty()) finish_deferred(now);
    if (now >= next_idle_check_) {
      close_idle(now);
      next_idle_check_ = now + kIdleCheckNs;
      if (accept_paused_until_ && now >= accept_paused_until_) {
        accept_paused_until_ = 0;
        watch(listen_fd_, kListenKey, EPOLLIN, false);
      }
    }
  }
}

void Server::accept_clients(std::int64_t now) {
  for (;;) {
    sockaddr_in a{};
    socklen_t len = sizeof a;
    const int fd = accept4(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        // Out of descriptors: stop listening for a moment rather than spin on a ready socket.
        watch(listen_fd_, kListenKey, 0, false);
        accept_paused_until_ = now + kIdleCheckNs;
      }
      return;  // EAGAIN: all taken; ECONNABORTED and the like: the client is gone
    }
    const std::uint32_t peer = ntohl(a.sin_addr.s_addr);
    const bool allowed = config_.allowed_clients.empty() ||
                         std::any_of(config_.allowed_clients.begin(), config_.allowed_clients.end(),
                                     [peer](const ClientNetwork& n) { return n.contains(peer); });
    if (!allowed || open_ >= slots_.size()) {
      // A clean refusal: the client sees the connection closed at once, before any
      // request. Counted first, so whoever sees the close also sees the count.
      counters_.refused.fetch_add(1, std::memory_order_relaxed);
      close(fd);
      if (audit_) audit_->refused(ClientAddress{peer, ntohs(a.sin_port)}, allowed ? "max_clients reached" : "not in allowed_clients");
      continue;
    }
    std::size_t slot = 0;
    while (slots_[slot]->fd >= 0) ++slot;
    Connection& c = *slots_[slot];
    c.fd = fd;
    c.peer = peer;
    c.peer_port = ntohs(a.sin_port);
    c.used = 0;
    c.paused = false;
    c.pending.active = false;
    c.last_request_ns = now;
    const int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);  // replies are small: never hold them back
    watch(fd, slot + 1, EPOLLIN | EPOLLRDHUP, true);
    ++open_;
    counters_.accepted.fetch_add(1, std::memory_order_relaxed);
    counters_.open.store(open_, std::memory_order_relaxed);
  }
}

void Server::on_readable(std::size_t slot, std::int64_t now) {
  Connection& c = *slots_[slot];
  // One recv per readiness: every ready connection gets its turn in each round.
  const ssize_t got = recv(c.fd, c.buf + c.used, kBufferSize - c.used, 0);
  if (got == 0) { close_connection(slot, counters_.closed_by_peer); return; }
  if (got < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return;
    close_connection(slot, counters_.closed_by_peer);
    return;
  }
  c.used += static_cast<std::size_t>(got);
  serve_frames(slot, now);
}

void Server::serve_frames(std::size_t slot, std::int64_t now) {
  Connection& c = *slots_[slot];
  std::size_t at = 0;
  while (c.fd >= 0) {
    const FrameCheck f = check_frame(c.buf + at, c.used - at);
    if (f.status == FrameStatus::Incomplete) break;
    if (f.status == FrameStatus::Bad) { close_connection(slot, counters_.closed_bad_frame); return; }
    handler_->set_client(ClientAddress{c.peer, c.peer_port});
    const auto outcome = handler_->handle(c.fd, c.buf + at, f.length, c.pending, now);
    at += f.length;
    c.last_request_ns = now;
    if (outcome == RequestHandler::Outcome::SendFailed) { close_connection(slot, counters_.closed_unsendable); return; }
    if (outcome == RequestHandler::Outcome::Deferred) {
      c.paused = true;
      watch(c.fd, slot + 1, EPOLLRDHUP, false);
      deferred_.push_back(slot);
      break;
    }
  }
  if (at) {
    std::memmove(c.buf, c.buf + at, c.used - at);
    c.used -= at;
  }
}

void Server::finish_deferred(std::int64_t now) {
  for (std::size_t i = 0; i < deferred_.size();) {
    const std::size_t slot = deferred_[i];
    Connection& c = *slots_[slot];
    if (c.fd < 0) { deferred_.erase(deferred_.begin() + static_cast<std::ptrdiff_t>(i)); continue; }
    if (!handler_->ready(c.pending, now)) { ++i; continue; }
    deferred_.erase(deferred_.begin() + static_cast<std::ptrdiff_t>(i));
    if (handler_->finish(c.fd, c.pending, now) != RequestHandler::Outcome::Sent) {
      close_connection(slot, counters_.closed_unsendable);
      continue;
    }
    c.paused = false;
    watch(c.fd, slot + 1, EPOLLIN | EPOLLRDHUP, false);
    serve_frames(slot, now);  // requests that arrived behind it
  }
}

void Server::close_idle(std::int64_t now) {
  if (config_.idle_timeout_ns <= 0) return;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const Connection& c = *slots_[i];
    if (c.fd >= 0 && !c.paused && now - c.last_request_ns > config_.idle_timeout_ns)
      close_connection(i, counters_.closed_idle);
  }
}

void Server::close_connection(std::size_t slot, std::atomic<std::uint64_t>& reason) {
  Connection& c = *slots_[slot];
  if (c.fd < 0) return;
  // A reply still waiting goes with it (the slot may be taken by a new client at once).
  if (c.paused) deferred_.erase(std::remove(deferred_.begin(), deferred_.end(), slot), deferred_.end());
  --open_;
  reason.fetch_add(1, std::memory_order_relaxed);  // before the client can see the close
  counters_.open.store(open_, std::memory_order_relaxed);
  if (epoll_fd_ >= 0) epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, c.fd, nullptr);
  close(c.fd);
  c.fd = -1;
  c.used = 0;
  c.paused = false;
  c.pending.active = false;
}

}  // namespace syncplc::modbus
