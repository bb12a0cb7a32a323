// timing: cycle — the modbus_client driver's exchanges follow the task's
// scans (docs/modbus-client.md, "Threads and timing"): over a real loopback
// socket, a device in this process that numbers its read replies and stamps
// every request's arrival, and a test thread that plays the task (latch,
// then outputs and their hand-over) on an irregular 10-24 ms schedule. The
// device thread is real: where a test judges what follows each hand-over,
// the played task waits for that exchange before its next scan (a loaded
// machine delays the scans, not the order of events), and the judgement is
// by the order of hand-overs, requests and latches, not by their times.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/io/modbus_client/modbus_client.hpp"
#include "tests/project/loader_test_util.hpp"

namespace syncplc {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// One request as the device saw it.
struct Seen {
  std::int64_t at;        // arrival, monotonic ns
  std::uint8_t function;  // 3 read, 6 write
  std::uint16_t value;    // read: the number the reply carries; write: the value written
};

// A Modbus TCP device on 127.0.0.1: FC 3 (one register) answered with the
// number of this read (1, 2, ...), FC 6 echoed; every request recorded.
class NumberingDevice {
 public:
  NumberingDevice() {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    socklen_t len = sizeof a;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
    listen(fd_, 4);
    thread_ = std::thread([this] { serve(); });
  }
  ~NumberingDevice() { stop(); }
  void stop() {
    if (!thread_.joinable()) return;
    stop_ = true;
    shutdown(fd_, SHUT_RDWR);
    close(fd_);
    thread_.join();
  }
  std::vector<Seen> seen() {
    std::lock_guard l(m_);
    return seen_;
  }
  std::uint16_t port = 0;

 private:
  void serve() {
    while (!stop_) {
      int c = accept(fd_, nullptr, nullptr);
      if (c < 0) return;
      timeval tv{0, 50'000};
      setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      std::uint8_t buf[260];
      std::size_t have = 0;
      while (!stop_) {
        ssize_t n = recv(c, buf + have, sizeof buf - have, 0);
        if (n == 0) break;
        if (n < 0) continue;  // receive timeout: look at stop_ again
        have += static_cast<std::size_t>(n);
        while (have >= 12) {  // both requests here are 12 bytes
          const std::int64_t now = monotonic_ns();
          std::uint8_t q[12];
          std::copy(buf, buf + 12, q);
          std::copy(buf + 12, buf + have, buf);
          have -= 12;
          std::vector<std::uint8_t> reply;
          std::uint16_t value = 0;
          if (q[7] == 3) {
            value = ++reads_;
            reply = {q[0], q[1], 0, 0, 0, 5, q[6], 3, 2, static_cast<std::uint8_t>(value >> 8), static_cast<std::uint8_t>(value)};
          } else {
            value = static_cast<std::uint16_t>(q[10] << 8 | q[11]);
            reply.assign(q, q + 12);
          }
          {
            std::lock_guard l(m_);
            seen_.push_back({now, q[7], value});
          }
          send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
        }
      }
      close(c);
    }
  }
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::uint16_t reads_ = 0;
  std::mutex m_;
  std::vector<Seen> seen_;
  std::thread thread_;
};

struct Client {
  Client(std::uint16_t port, ExchangeTiming timing) {
    ModbusClientConfig cfg;
    ClientDevice d;
    d.name = "dev";
    d.port = port;
    d.response_timeout_ns = 100 * kMs;
    d.reconnect_min_ns = 10 * kMs;
    d.reconnect_max_ns = 20 * kMs;
    d.timing = timing;
    d.task_period_ns = 10 * kMs;
    cfg.devices.push_back(d);
    RequestGroup r;  // listed first: the burst still writes first
    r.name = "r";
    r.function = ModbusFunction::ReadHoldingRegisters;
    r.interval_ns = 10 * kMs;
    cfg.groups.push_back(r);
    RequestGroup w;
    w.name = "w";
    w.function = ModbusFunction::WriteSingleRegister;
    w.address = 5;
    w.interval_ns = 10 * kMs;
    cfg.groups.push_back(w);
    driver = std::make_unique<ModbusClientDriver>(cfg);
    cells.assign(driver->channels().size(), Cell{});
    std::vector<Cell*> ptrs;
    for (auto& c : cells) ptrs.push_back(&c);
    driver->set_name("io");
    driver->bind(ptrs);
    std::string err;
    EXPECT_TRUE(driver->open(&err)) << err;
  }
  ~Client() { driver->close(); }
  Cell& ch(const char* name) { return cells[static_cast<std::size_t>(driver->channel_index(name))]; }
  std::unique_ptr<ModbusClientDriver> driver;
  std::vector<Cell> cells;
};

void sleep_until(std::int64_t t) {
  const std::int64_t left = t - monotonic_ns();
  if (left > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(left));
}

// What the task saw: per scan k, the value latched at its start and when
// its outputs (the value k) were handed over.
struct Scans {
  std::vector<std::int64_t> hand_over;
  std::vector<int> latched;
};

// Scans on an irregular schedule (gaps 10, 16, 10, 24 ms: a free-running
// 10 ms grid puts two or three requests into the long gaps); scan k writes k.
// With `dev` (timing cycle), a scan also waits until the exchange of the
// last hand-over (its write, then a read) has been answered and the reply is
// in the driver, so a
// device thread that a loaded machine holds back delays the scans instead of
// missing them (the minute per scan only ends a hang).
Scans play_task(Client& cl, int n, NumberingDevice* dev = nullptr) {
  ScanContext ctx;
  Scans s;
  const std::int64_t gaps[] = {10 * kMs, 16 * kMs, 10 * kMs, 24 * kMs};
  std::int64_t next = monotonic_ns();
  for (int k = 0; k < n; ++k) {
    sleep_until(next);
    if (dev && k > 0) {
      const std::int64_t guard = monotonic_ns() + 60'000 * kMs;
      // The number of the read after the write of the last hand-over's
      // value k - 1 (an earlier scan's exchange may still end after it).
      int answer = -1;
      while (answer < 0 && monotonic_ns() < guard) {
        bool written = false;
        for (const auto& q : dev->seen()) {
          if (q.at > s.hand_over.back() && q.function == 6 && q.value == k - 1) written = true;
          else if (written && q.function == 3) {
            answer = q.value;
            break;
          }
        }
        if (answer < 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      while (monotonic_ns() < guard) {  // its reply through the driver
        cl.driver->latch_inputs(ctx);
        if (cl.ch("r_ok").get<bool>() && cl.ch("r").get<std::int16_t>() >= answer) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      next = std::max(next, monotonic_ns());
    }
    cl.driver->latch_inputs(ctx);
    s.latched.push_back(cl.ch("r_ok").get<bool>() ? cl.ch("r").get<std::int16_t>() : -1);
    cl.ch("w").set<std::int16_t>(static_cast<std::int16_t>(k));
    s.hand_over.push_back(monotonic_ns());
    cl.driver->write_outputs(ctx);
    next += gaps[k % 4];
  }
  return s;
}

// Until the device thread has connected and exchanged once (the guard, a
// minute of 5 ms scans, only ends a hang).
void wait_connected(Client& cl) {
  ScanContext ctx;
  for (int i = 0; i < 12000; ++i) {
    cl.driver->latch_inputs(ctx);
    if (cl.ch("r_ok").get<bool>()) return;
    cl.driver->write_outputs(ctx);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  FAIL() << "the device thread did not connect";
}

struct Verdict {
  std::string odd;   // the scans that did not follow: their requests (function:value@us after the hand-over)
  int late = 0;      // scans not judged: the task itself handed over no outputs for kFallback (below)
  int scans = 0;     // scans judged
  int followed = 0;  // exactly one write then one read between the hand-over and the next, the write carrying the scan's value
  int latched = 0;   // the next scan latched the reply of that read
};

// A task that hands over nothing for three of its periods gets the device
// thread's own grid (device_link.hpp, kFallbackPeriods): those scans are the
// task's lateness (the test thread's, on a loaded machine), not the
// driver's, and with `excuse_late` are counted apart instead of judged.
constexpr std::int64_t kFallback = 3 * 10 * kMs;

Verdict judge(const Scans& s, const std::vector<Seen>& seen, int first, bool excuse_late = false) {
  Verdict v;
  for (std::size_t k = static_cast<std::size_t>(first); k + 1 < s.hand_over.size(); ++k) {
    if (excuse_late && s.hand_over[k + 1] - s.hand_over[k] >= kFallback) {
      ++v.late;
      continue;
    }
    ++v.scans;
    std::vector<Seen> in;  // the requests between this hand-over and the next
    for (const auto& q : seen)
      if (q.at > s.hand_over[k] && q.at <= s.hand_over[k + 1]) in.push_back(q);
    const bool one_each = in.size() == 2 && in[0].function == 6 && in[1].function == 3;
    if (one_each && in[0].value == k) ++v.followed;
    else {
      v.odd += "scan " + std::to_string(k) + ":";
      for (const auto& q : in)
        v.odd += " " + std::to_string(q.function) + ":" + std::to_string(q.value) + "@" +
                 std::to_string((q.at - s.hand_over[k]) / 1000) + "us";
      v.odd += "\n";
    }
    if (one_each && s.latched[k + 1] == in[1].value) ++v.latched;
  }
  return v;
}

// Every scan's hand-over is followed by its write and then its read, before
// the next hand-over, once per scan, and the next scan latches exactly that
// read's reply: no repeated and no skipped sample. Judged by the order of
// events (hand-overs, requests, latches), not by their times. (`timing: free` fails it:
// its 10 ms grid ignores the scans, test below.)
TEST(ModbusClientCycle, TheExchangeFollowsEachScansHandOver) {
  NumberingDevice dev;
  Client cl(dev.port, ExchangeTiming::Cycle);
  wait_connected(cl);
  // Rounds of 40 scans until 30 are judged (a loaded machine may make the
  // played task late for some; ten rounds at most).
  Verdict all;
  for (int round = 0; round < 10 && all.scans < 30; ++round) {
    const Scans s = play_task(cl, 40, &dev);
    const Verdict v = judge(s, dev.seen(), 1, true);
    all.scans += v.scans;
    all.late += v.late;
    all.followed += v.followed;
    all.latched += v.latched;
    all.odd += v.odd;
  }
  std::printf("%d scans judged, %d late (the played task's own lateness)\n", all.scans, all.late);
  ASSERT_GE(all.scans, 30);
  EXPECT_EQ(all.followed, all.scans) << all.followed << " of " << all.scans << "\n" << all.odd;
  // Exactly one read per scan, and the next scan latched its reply: no
  // repeated and no skipped sample.
  EXPECT_EQ(all.latched, all.scans) << all.latched << " of " << all.scans;
}

// The free-running grid (the old timing, kept as `timing: free`) does not
// follow the scans: every 24 ms gap (a quarter of the scans) holds two or
// three of its requests, so it fails the check above (at most scans - 4),
// whatever its phase.
TEST(ModbusClientCycle, TheFreeGridDoesNotFollowTheScans) {
  NumberingDevice dev;
  Client cl(dev.port, ExchangeTiming::Free);
  wait_connected(cl);
  const Scans s = play_task(cl, 40);
  const Verdict v = judge(s, dev.seen(), 1);
  EXPECT_LE(v.followed, v.scans - v.scans / 4 + 1) << v.followed << " of " << v.scans;
}

// A task that stops scanning: after kFallbackPeriods periods without a
// hand-over the device thread exchanges on the groups' own 10 ms grid, so a
// dead device is still seen, and its staleness is there at the next latch.
TEST(ModbusClientCycle, WithoutScansTheDeviceThreadFallsBackToItsOwnGrid) {
  NumberingDevice dev;
  Client cl(dev.port, ExchangeTiming::Cycle);
  wait_connected(cl);
  play_task(cl, 5);
  const std::int64_t last = monotonic_ns();
  // Five reads without a scan (counted; the minute only ends a hang), and no
  // more than one per 10 ms of the time that took: the groups' own grid,
  // not a busy loop.
  auto reads_since = [&] {
    int n = 0;
    for (const auto& q : dev.seen()) n += q.at > last && q.function == 3;
    return n;
  };
  while (reads_since() < 5 && monotonic_ns() - last < 60'000 * kMs)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const std::int64_t waited = monotonic_ns() - last;
  const int reads = reads_since();
  EXPECT_GE(reads, 5);
  EXPECT_LE(reads, waited / (10 * kMs) + 2) << waited / kMs << " ms";
  dev.stop();
  ScanContext ctx;
  bool stale = false;
  for (int i = 0; i < 6000 && !stale; ++i) {  // no scan hands over: only the fallback can see it (a minute: a hang guard)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    cl.driver->latch_inputs(ctx);
    stale = !cl.ch("r_ok").get<bool>();
  }
  EXPECT_TRUE(stale);
}

// A duration group (every 30 ms, a 10 ms task) is exchanged at the scans
// nearest its grid: once every third scan, never between scans.
TEST(ModbusClientCycle, ADurationGroupGoesWithTheScanNearestItsTime) {
  NumberingDevice dev;
  ModbusClientConfig cfg;
  ClientDevice d;
  d.name = "dev";
  d.port = dev.port;
  d.task_period_ns = 10 * kMs;
  cfg.devices.push_back(d);
  RequestGroup r;
  r.name = "r";
  r.function = ModbusFunction::ReadHoldingRegisters;
  r.interval_ns = 30 * kMs;
  r.every_scan = false;
  cfg.groups.push_back(r);
  ModbusClientDriver drv(cfg);
  std::vector<Cell> cells(drv.channels().size());
  std::vector<Cell*> ptrs;
  for (auto& c : cells) ptrs.push_back(&c);
  drv.set_name("io");
  drv.bind(ptrs);
  std::string err;
  ASSERT_TRUE(drv.open(&err)) << err;
  ScanContext ctx;
  std::vector<std::int64_t> hand_over;
  const std::int64_t opened = monotonic_ns();
  std::int64_t next = opened;
  for (int k = 0; k < 40; ++k) {
    sleep_until(next);
    drv.latch_inputs(ctx);
    hand_over.push_back(monotonic_ns());
    drv.write_outputs(ctx);
    next += 10 * kMs;
  }
  drv.close();
  const auto seen = dev.seen();
  // Counted between the scans' hand-overs: never two requests between two
  // hand-overs (at most once a scan), and about one per three scans; a
  // loaded machine stretches the scans, not these counts.
  std::vector<int> per_scan(hand_over.size() + 1, 0);
  for (const auto& q : seen)
    ++per_scan[static_cast<std::size_t>(std::upper_bound(hand_over.begin(), hand_over.end(), q.at) - hand_over.begin())];
  int doubled = 0;
  for (std::size_t k = 1; k < per_scan.size(); ++k) doubled += per_scan[k] > 1;
  EXPECT_LE(doubled, 1) << "requests between scans, more than one in an interval";
  // 40 scans at one per three: about 13 (the first at the connection); never
  // more than one per 30 ms of the time the scans took, however long.
  EXPECT_GE(seen.size(), 9u);
  EXPECT_LE(static_cast<std::int64_t>(seen.size()), (hand_over.back() - opened) / (30 * kMs) + 2);
}

TEST(ModbusClientCycle, TimingIsADeviceSetting) {
  auto r = loadertest::load(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices:
      - {name: a, port: 5020}
      - {name: b, port: 5021, timing: free}
    groups:
      - {name: g, device: a, function: 3, address: 0}
      - {name: h, device: b, function: 3, address: 0, every: 50ms}
)");
  ASSERT_LOADS(r);
  const auto& c = static_cast<ModbusClientDriver&>(*r.program->drivers[0].driver).config();
  EXPECT_EQ(c.devices[0].timing, ExchangeTiming::Cycle);  // the default
  EXPECT_EQ(c.devices[1].timing, ExchangeTiming::Free);
  EXPECT_EQ(c.devices[0].task_period_ns, 10 * kMs);
  EXPECT_TRUE(c.groups[0].every_scan);
  EXPECT_FALSE(c.groups[1].every_scan);
  auto e = loadertest::errors(R"(
tasks: [{name: main, period: 10ms}]
drivers:
  - name: io
    type: modbus_client
    devices: [{name: a, port: 5020, timing: sync}]
    groups: [{name: g, function: 3, address: 0}]
)");
  EXPECT_THAT(e, loadertest::has_error("p.yaml:5:45", "timing must be one of cycle, free, not 'sync'"));
}

}  // namespace
}  // namespace syncplc
