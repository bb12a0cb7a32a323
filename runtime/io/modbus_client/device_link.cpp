#include "runtime/io/modbus_client/device_link.hpp"

#include <pthread.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/io/modbus_client/wire_values.hpp"

namespace syncplc {

DeviceLink::DeviceLink(const ClientDevice& d, std::vector<GroupHandover*> groups, Clock clock, CycleSignal* signal)
    : device_(&d), groups_(std::move(groups)), clock_(clock), signal_(signal) {
  // Writes, then read/writes (FC 23), then reads: a burst's reads see the
  // device after this scan's writes.
  auto rank = [](const GroupHandover* g) { return g->group->reads() ? (g->group->writes() ? 1 : 2) : 0; };
  std::stable_sort(groups_.begin(), groups_.end(),
                   [&](const GroupHandover* a, const GroupHandover* b) { return rank(a) < rank(b); });
}

bool DeviceLink::start(std::string* error) {
  stop_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (stop_fd_ < 0) {
    if (error) *error = std::string("modbus_client: eventfd: ") + std::strerror(errno);
    return false;
  }
  link_.set_stop_fd(stop_fd_);
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) {
    if (error) *error = std::string("modbus_client: eventfd: ") + std::strerror(errno);
    ::close(stop_fd_);
    stop_fd_ = -1;
    return false;
  }
  link_.set_wake_fd(wake_fd_);
  stopping_.store(false, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
  // Names show in top -H and gdb; at most 15 characters.
  const std::string name = ("mb:" + device_->name).substr(0, 15);
  pthread_setname_np(thread_.native_handle(), name.c_str());
  return true;
}

void DeviceLink::stop() noexcept {
  if (!thread_.joinable()) return;
  stopping_.store(true, std::memory_order_seq_cst);
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(stop_fd_, &one, sizeof one);
  signal_->hand_over();  // ends a wait for the scan (the other devices see one more hand-over: a burst, harmless)
  thread_.join();
  ::close(stop_fd_);
  ::close(wake_fd_);
  stop_fd_ = wake_fd_ = -1;
  link_.set_wake_fd(-1);
}

int DeviceLink::release() noexcept {
  if (!thread_.joinable()) return -1;
  releasing_.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(wake_fd_, &one, sizeof one);
  signal_->hand_over();  // ends a wait for the scan (timing cycle), as stop() does
  thread_.join();
  ::close(stop_fd_);
  ::close(wake_fd_);
  stop_fd_ = wake_fd_ = -1;
  link_.set_stop_fd(-1);
  link_.set_wake_fd(-1);
  return link_.release();
}

void DeviceLink::adopt(int fd) noexcept {
  if (!thread_.joinable()) {
    if (fd >= 0) ::close(fd);
    return;
  }
  adopted_.store(fd, std::memory_order_release);
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(wake_fd_, &one, sizeof one);
  signal_->hand_over();
}

void DeviceLink::flush() noexcept {
  if (!thread_.joinable()) return;
  flush_.store(true, std::memory_order_release);
  const std::uint64_t one = 1;
  [[maybe_unused]] ssize_t n = ::write(wake_fd_, &one, sizeof one);
  signal_->hand_over();
}

void DeviceLink::fail_others(const GroupHandover* except, ClientError e) {
  const std::int64_t now = clock_();
  for (auto* g : groups_)
    if (g != except) g->publish(code(e), now, nullptr, now, epoch_, request_cycle());
}

std::uint32_t DeviceLink::request_cycle() const noexcept {
  // timing cycle: the hand-over this burst serves; free (and the fallback):
  // the hand-overs so far.
  return follows_scan_ ? seen_ : signal_->count();
}

bool DeviceLink::exchange(GroupHandover& h, std::uint16_t* error) {
  const RequestGroup& g = *h.group;
  const std::uint32_t w = g.format.width();
  std::uint64_t seq = 0;  // writes: the outputs' sequence number this request writes
  ClientRequest r;
  r.function = g.function;
  r.unit = device_->unit;
  r.address = g.address;
  r.quantity = static_cast<std::uint16_t>(g.count * w);
  bool write = g.writes();
  const Cell* out = nullptr;  // one acquire: seq, epoch and values of one hand-over
  if (write) {
    out = h.outputs.acquire();
    seq = out[GroupHandover::kSeq].get<std::uint64_t>();
    if (seq == 0) return false;  // no scan has handed outputs over yet
    // The write gate: outputs computed before this connection's first good
    // reads are not sent (a drive would get a target from stale data).
    const std::uint64_t epoch = out[GroupHandover::kOutEpoch].get<std::uint64_t>();
    if (epoch != GroupHandover::kAnyEpoch && epoch != epoch_) {
      if (!g.reads()) return false;
      write = false;  // FC 23: its read side alone, as FC 3
      r.function = ModbusFunction::ReadHoldingRegisters;
    }
  }
  if (write) {
    const Cell* v = out + GroupHandover::kOutValues;
    const std::uint32_t n = g.written_values();
    // on_change: nothing new to write, unless alive_every has passed since
    // the last write (the same values again: the device's liveness check).
    if (g.on_change && h.have_written &&
        std::equal(v, v + n, h.written.begin(), [](const Cell& a, const Cell& b) { return a.raw == b.raw; }) &&
        (g.alive_every_ns == 0 || monotonic_ns() - h.written_ns < g.alive_every_ns)) {
      h.acked.store(seq, std::memory_order_release);  // the device has these values already
      return false;
    }
    std::copy(v, v + n, h.written.begin());  // what this request writes; acknowledged below
    h.written_ns = monotonic_ns();
    if (g.format.wire == IecType::BOOL) {
      values_to_bits(v, n, h.bits.data());
      r.bits = h.bits.data();
    } else {
      values_to_registers(g.format, v, n, h.regs.data());
      r.registers = h.regs.data();
    }
    if (g.function == ModbusFunction::ReadWriteMultipleRegisters) {
      r.write_address = g.write_address;
      r.write_quantity = static_cast<std::uint16_t>(g.write_count * w);
    }
  }
  r.transaction = ++transaction_;
  std::uint8_t buf[kMaxAdu];
  const std::size_t len = build_request(r, buf);
  h.requests.fetch_add(1, std::memory_order_relaxed);
  const std::uint32_t cycle = request_cycle();
  const std::int64_t sent = clock_();
  const std::int64_t deadline = monotonic_ns() + device_->response_timeout_ns;
  ClientError e = link_.send_all(buf, len, deadline);
  std::size_t got = 0;
  if (e == ClientError::None) e = link_.receive(buf, kMbapBytes, deadline);
  if (e == ClientError::None) {
    const std::size_t length = mbap_length(buf);
    if (buf[2] != 0 || buf[3] != 0 || length < 2) e = ClientError::Malformed;  // not Modbus TCP: read no further
    else if (length > kMaxAdu - 6) e = ClientError::Oversized;
    else {
      e = link_.receive(buf + kMbapBytes, length - 1, deadline);
      if (e == ClientError::ConnectionLost) e = ClientError::Short;  // closed after the header
      got = 6 + length;
    }
  }
  if (e == ClientError::None) {
    const ClientReply reply = parse_reply(r, buf, got);
    e = reply.error;
    if (e == ClientError::None && g.reads()) {
      if (g.format.wire == IecType::BOOL) values_from_bits(reply.data, g.count, h.read.data());
      else values_from_registers(g.format, reply.data, g.count, h.read.data());
    }
  }
  // An exchange cut short by stop() is the driver closing, not the device failing: not a result.
  if (stopping_.load(std::memory_order_acquire)) return true;
  if (e == ClientError::None && write) {
    h.have_written = true;
    h.acked.store(seq, std::memory_order_release);
  }
  if (e != ClientError::None && write) h.have_written = false;  // write again, whatever on_change says
  *error = code(e);
  h.publish(code(e), clock_(), e == ClientError::None ? h.read.data() : nullptr, sent, epoch_, cycle);
  return true;
}

void DeviceLink::backoff_after_failure() {
  next_connect_ = monotonic_ns() + backoff_;
  backoff_ = std::min(2 * backoff_, device_->reconnect_max_ns);
}

bool DeviceLink::settle(GroupHandover& g, std::uint16_t err) {
  if (!keeps_connection(err)) {
    link_.close();
    fail_others(&g, ClientError::NotConnected);
    backoff_after_failure();
    return false;
  }
  if (err == 0) backoff_ = device_->reconnect_min_ns;
  return true;
}

void DeviceLink::run_free() {
  GroupHandover* due = *std::min_element(groups_.begin(), groups_.end(),
                                         [](const GroupHandover* a, const GroupHandover* b) { return a->next_due < b->next_due; });
  const std::int64_t now = monotonic_ns();
  if (due->next_due > now) {
    // timing cycle (the fallback): a hand-over ends the wait too.
    if (follows_scan_) signal_->wait(seen_, due->next_due, stopping_);
    else link_.wait_until(due->next_due);
    return;
  }
  // The next exchange on the group's own grid; never a burst to catch up.
  due->next_due = std::max(due->next_due + due->group->interval_ns, now);
  std::uint16_t err = 0;
  if (!exchange(*due, &err) || stopping_.load(std::memory_order_acquire)) return;
  settle(*due, err);
}

void DeviceLink::run_burst(std::int64_t now) {
  // A duration group is due at the hand-over nearest its time on its grid.
  const std::int64_t half = device_->task_period_ns / 2;
  for (auto* g : groups_) {  // writes first (the constructor's order), so a read sees this scan's writes done
    if (stopping_.load(std::memory_order_acquire)) return;
    const RequestGroup& rg = *g->group;
    if (!rg.every_scan && g->next_due > now + half) continue;
    // Where the fallback (the group's own grid) would exchange it next.
    g->next_due = rg.every_scan ? now + rg.interval_ns : std::max(g->next_due + rg.interval_ns, now);
    std::uint16_t err = 0;
    if (!exchange(*g, &err)) continue;
    if (stopping_.load(std::memory_order_acquire)) return;
    if (!settle(*g, err)) return;  // closed: the others failed with it, reconnect first
  }
}

void DeviceLink::run() {
  backoff_ = device_->reconnect_min_ns;
  next_connect_ = monotonic_ns();
  bool ever = false;
  if (inherit_) {
    // Online change: the predecessor's connection, or none (connect below).
    while (!stopping_.load(std::memory_order_acquire) && !releasing_.load(std::memory_order_acquire) &&
           adopted_.load(std::memory_order_acquire) == kAwaiting)
      link_.wait_until(std::numeric_limits<std::int64_t>::max());
    const int fd = adopted_.exchange(kAwaiting, std::memory_order_acq_rel);
    if (fd >= 0) {
      link_.adopt(fd);
      epoch_ = connects.fetch_add(1, std::memory_order_relaxed) + 1;
      ever = true;  // the device's connection goes on: a later one is a reconnection
    }
    next_connect_ = monotonic_ns();
  }
  for (auto* g : groups_) g->next_due = next_connect_;
  // A driver built without a task (period 0) has no hand-overs to follow.
  follows_scan_ = device_->timing == ExchangeTiming::Cycle && device_->task_period_ns > 0;
  const std::int64_t fallback = kFallbackPeriods * device_->task_period_ns;
  seen_ = signal_->count();
  last_hand_over_ = monotonic_ns();
  while (!stopping_.load(std::memory_order_acquire) && !releasing_.load(std::memory_order_acquire)) {
    if (flush_.exchange(false, std::memory_order_acq_rel)) {
      // at_stop: the write groups at once (timing cycle: flush() also hands
      // over, so the burst below takes them).
      const std::int64_t now = monotonic_ns();
      next_connect_ = std::min(next_connect_, now);
      for (auto* g : groups_)
        if (g->group->writes()) g->next_due = now;
    }
    if (!link_.connected()) {
      if (monotonic_ns() < next_connect_) {
        link_.wait_until(next_connect_);
        continue;
      }
      // The address open() resolved: no name lookup here, where stop() must end every wait at once.
      const ClientError e = link_.connect(device_->address.empty() ? device_->host : device_->address, device_->port,
                                          device_->connect_timeout_ns);
      if (stopping_.load(std::memory_order_acquire)) break;
      if (e != ClientError::None) {
        fail_others(nullptr, e);
        backoff_after_failure();
        continue;
      }
      epoch_ = connects.fetch_add(1, std::memory_order_relaxed) + 1;  // a new connection: the write gate closes
      if (ever) reconnects.fetch_add(1, std::memory_order_relaxed);
      ever = true;
      const std::int64_t now = monotonic_ns();
      for (auto* g : groups_) {
        g->next_due = std::min(g->next_due, now);  // exchange at once after a reconnect
        g->have_written = false;  // a restarted device may have lost them: write again, on_change or not
      }
      // timing cycle: a scan that handed over while the link was down is
      // served at once (count != seen_ below), as `free` exchanges at once.
    }
    if (!follows_scan_) {
      run_free();
      continue;
    }
    const std::uint32_t count = signal_->count();
    if (count != seen_) {
      seen_ = count;
      last_hand_over_ = monotonic_ns();
      run_burst(last_hand_over_);
      continue;
    }
    if (monotonic_ns() - last_hand_over_ < fallback) {
      signal_->wait(seen_, last_hand_over_ + fallback, stopping_);
      continue;
    }
    run_free();  // no scan for a while: the groups' own grid until the next hand-over
  }
  if (!releasing_.load(std::memory_order_acquire)) link_.close();  // released: the successor takes the socket
}

}  // namespace syncplc
