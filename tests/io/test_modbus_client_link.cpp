// The modbus_client driver's device thread over real sockets against a fake
// device in this process that answers with one kind of bad reply each: every
// class ends as its error code in the group's status, the connection is
// closed and opened again (or kept, for an exception reply), nothing crashes.
// The tests wait for conditions (an error code, a number of requests or
// connections); a wait ends by time only as a guard against a hang
// (kHangGuard), so a loaded machine makes them slower, not wrong.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "runtime/io/modbus_client/modbus_client.hpp"

namespace syncplc {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;

constexpr auto kHangGuard = std::chrono::seconds(60);

// Polls `done` every millisecond until it holds or the hang guard runs out.
template <class F>
bool eventually(F done) {
  const auto guard = Clock::now() + kHangGuard;
  while (!done()) {
    if (Clock::now() > guard) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Accepts connections on 127.0.0.1 and answers each request with answer(request)
// (nothing for an empty answer; a last byte 0xEE closes the connection after the rest).
class FakeDevice {
 public:
  explicit FakeDevice(std::function<Bytes(const Bytes&)> answer) : answer_(std::move(answer)) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    socklen_t len = sizeof a;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
    listen(fd_, 8);
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeDevice() {
    stop_ = true;
    shutdown(fd_, SHUT_RDWR);
    close(fd_);
    thread_.join();
  }
  std::uint16_t port = 0;
  std::atomic<int> connections{0};

 private:
  void serve() {
    while (!stop_) {
      int c = accept(fd_, nullptr, nullptr);
      if (c < 0) return;
      ++connections;
      timeval tv{0, 200'000};
      setsockopt(c, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
      while (!stop_) {
        std::uint8_t buf[300];
        ssize_t n = recv(c, buf, sizeof buf, 0);
        if (n == 0) break;
        if (n < 0) continue;  // receive timeout: look at stop_ again
        Bytes reply = answer_(Bytes(buf, buf + n));
        // A last byte 0xEE: send the bytes before it, then close the connection.
        const bool close_after = !reply.empty() && reply.back() == 0xEE;
        if (close_after) reply.pop_back();
        if (!reply.empty()) send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
        if (close_after) break;
      }
      close(c);
    }
  }
  std::function<Bytes(const Bytes&)> answer_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// The reply to a read of one holding register (FC 3) with its MBAP copied from the request.
Bytes good(const Bytes& req) { return {req[0], req[1], 0, 0, 0, 5, req[6], 3, 2, 0x01, 0x02}; }

struct Client {
  struct Options {
    std::int64_t reconnect_min = 10'000'000, reconnect_max = 20'000'000;
    std::int64_t interval_ns = 5'000'000;
    bool open = true;
    std::int64_t response_timeout = 100'000'000;
  };
  explicit Client(std::uint16_t port, std::int64_t reconnect_min = 10'000'000, std::int64_t reconnect_max = 20'000'000)
      : Client(port, Options{reconnect_min, reconnect_max}) {}
  Client(std::uint16_t port, const Options& o) {
    ModbusClientConfig cfg;
    ClientDevice d;
    d.name = "dev";
    d.port = port;
    d.response_timeout_ns = o.response_timeout;
    d.reconnect_min_ns = o.reconnect_min;
    d.reconnect_max_ns = o.reconnect_max;
    cfg.devices.push_back(d);
    RequestGroup g;
    g.name = "g";
    g.function = ModbusFunction::ReadHoldingRegisters;
    g.count = 1;
    g.interval_ns = o.interval_ns;
    cfg.groups.push_back(g);
    driver = std::make_unique<ModbusClientDriver>(cfg);
    cells.assign(driver->channels().size(), Cell{});
    std::vector<Cell*> ptrs;
    for (auto& c : cells) ptrs.push_back(&c);
    driver->set_name("io");
    driver->bind(ptrs);
    std::string err;
    if (o.open) {
      EXPECT_TRUE(driver->open(&err)) << err;
    }
  }
  ~Client() { driver->close(); }
  Cell& ch(const char* name) { return cells[static_cast<std::size_t>(driver->channel_index(name))]; }
  // Latches until the group's error is `code` (or the hang guard runs out).
  bool wait_error(std::uint16_t code) {
    ScanContext ctx;
    return eventually([&] {
      driver->latch_inputs(ctx);
      return ch("g_error").get<std::uint16_t>() == code;
    });
  }
  std::unique_ptr<ModbusClientDriver> driver;
  std::vector<Cell> cells;
};

struct Case {
  const char* what;
  std::function<Bytes(const Bytes&)> answer;
  ClientError expect;
};

TEST(ModbusClientLink, EveryBadReplyEndsAsItsCodeAndTheDeviceIsReconnected) {
  const std::vector<Case> cases = {
      {"good", good, ClientError::None},
      {"exception 02", [](const Bytes& q) { return Bytes{q[0], q[1], 0, 0, 0, 3, q[6], 0x83, 2}; }, exception_error(2)},
      {"no answer", [](const Bytes&) { return Bytes{}; }, ClientError::Timeout},
      {"closed", [](const Bytes&) { return Bytes{0xEE}; }, ClientError::ConnectionLost},
      {"header then close", [](const Bytes& q) { return Bytes{q[0], q[1], 0, 0, 0, 5, q[6], 0xEE}; }, ClientError::Short},
      {"wrong transaction", [](const Bytes& q) { Bytes r = good(q); r[1] ^= 1; return r; }, ClientError::WrongTransaction},
      {"wrong unit", [](const Bytes& q) { Bytes r = good(q); r[6] ^= 1; return r; }, ClientError::WrongUnit},
      {"wrong function", [](const Bytes& q) { Bytes r = good(q); r[7] = 4; return r; }, ClientError::WrongFunction},
      {"protocol id", [](const Bytes& q) { Bytes r = good(q); r[3] = 9; return r; }, ClientError::Malformed},
      {"length field 600", [](const Bytes& q) { Bytes r = good(q); r[4] = 2; r[5] = 0x58; return r; }, ClientError::Oversized},
      {"byte count", [](const Bytes& q) { return Bytes{q[0], q[1], 0, 0, 0, 7, q[6], 3, 4, 0, 1, 0, 2}; }, ClientError::WrongByteCount},
      {"trailing byte", [](const Bytes& q) { return Bytes{q[0], q[1], 0, 0, 0, 6, q[6], 3, 2, 0, 1, 9}; }, ClientError::Oversized},
  };
  for (const auto& c : cases) {
    FakeDevice dev(c.answer);
    Client cl(dev.port);
    EXPECT_TRUE(cl.wait_error(code(c.expect))) << c.what << ": error " << cl.ch("g_error").get<std::uint16_t>();
    EXPECT_EQ(cl.ch("g_ok").get<bool>(), c.expect == ClientError::None) << c.what;
    if (c.expect == ClientError::None) {
      EXPECT_EQ(cl.ch("g").get<std::int16_t>(), 0x0102);
    }
    if (c.expect != ClientError::None && !keeps_connection(code(c.expect))) {
      // The connection was given up and made again, with back-off.
      EXPECT_TRUE(eventually([&] { return dev.connections >= 2; })) << c.what << ": not reconnected";
    }
  }
}

TEST(ModbusClientLink, NoDeviceListeningIsAConnectFailure) {
  int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  close(s);  // a port nobody listens on
  // Back-off from 10 ms doubling to 80 ms: six attempts are at least
  // 10 + 20 + 40 + 80 + 80 = 230 ms apart from first to last, where a fixed
  // 10 ms would take 50 ms. Counted attempts and a lower bound on their
  // time: a loaded machine only makes them later.
  const auto t0 = Clock::now();
  Client cl(ntohs(a.sin_port), 10'000'000, 80'000'000);
  EXPECT_TRUE(cl.wait_error(code(ClientError::ConnectFailed)));
  ScanContext ctx;
  EXPECT_TRUE(eventually([&] {
    cl.driver->latch_inputs(ctx);
    return cl.ch("g_errors").get<std::uint32_t>() >= 6;
  }));
  EXPECT_GE(Clock::now() - t0, std::chrono::milliseconds(230)) << "six attempts without the back-off";
  EXPECT_FALSE(cl.ch("g_ok").get<bool>());
}

double counter(const ModbusClientDriver& d, const std::string& name) {
  for (const auto& [k, v] : d.counters())
    if (k == name) return v;
  ADD_FAILURE() << "no counter " << name;
  return -1;
}

// Requests/s and the round trips over a real socket, against a device that
// takes 2 ms to answer; the group is due every 5 ms and the "scan" latches
// every 1 ms. The rate is checked against the requests counted and the
// time the driver was open as this test measured it from outside (before
// open, after close) and inside (after open, before close): whatever the
// load, requests / outside <= rate <= requests / inside; and never more
// than one request per 5 ms (plus the first).
TEST(ModbusClientLink, RequestsPerSecondAndRoundTripsAreCounted) {
  FakeDevice dev([](const Bytes& q) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    return good(q);
  });
  const auto outside0 = Clock::now();
  Client cl(dev.port);
  const auto inside0 = Clock::now();
  ScanContext ctx;
  EXPECT_TRUE(eventually([&] {
    cl.driver->latch_inputs(ctx);
    return cl.ch("g_requests").get<std::uint32_t>() >= 40;
  }));
  const auto inside1 = Clock::now();
  cl.driver->close();
  const auto outside1 = Clock::now();
  const double rate = counter(*cl.driver, "g.requests_per_s");
  const double requests = counter(*cl.driver, "g.requests");
  const auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
  EXPECT_GE(rate, requests / seconds(outside1 - outside0) * 0.999) << requests << " requests";
  EXPECT_LE(rate, requests / seconds(inside1 - inside0) * 1.001) << requests << " requests";
  EXPECT_LE(requests, seconds(outside1 - outside0) / 0.005 + 1) << "more often than every 5 ms";
  EXPECT_DOUBLE_EQ(counter(*cl.driver, "dev.requests_per_s"), rate);  // the device's only group
  // Every reply takes the device's 2 ms, and every latched one at least that
  // (histogram buckets: within 1/32). The two are not compared with each
  // other: a reply a stalled latch never took (a newer one came) is counted
  // in reply_* only.
  EXPECT_GE(counter(*cl.driver, "g.reply_p50_us"), 2000.0 * 31 / 32);
  EXPECT_GE(counter(*cl.driver, "g.latched_p50_us"), 2000.0 * 31 / 32);
  EXPECT_GE(counter(*cl.driver, "g.latched_max_us"), 2000.0 * 31 / 32);
  // Closed: the rate stays that of the time open.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_DOUBLE_EQ(counter(*cl.driver, "g.requests_per_s"), rate);
}

// Closing the driver interrupts the exchange under way: that is not the
// device's failure, and counts as no error (run prints the counters after it).
TEST(ModbusClientLink, AnExchangeCutShortByCloseIsNoError) {
  FakeDevice dev([](const Bytes&) { return Bytes{}; });  // never answers
  Client::Options o;
  o.response_timeout = 60'000'000'000;  // the close, not a timeout, ends the exchange, however late it comes
  Client cl(dev.port, o);
  EXPECT_TRUE(eventually([&] { return counter(*cl.driver, "g.requests") >= 1; }));
  ASSERT_GE(counter(*cl.driver, "g.requests"), 1.0);
  cl.driver->close();
  EXPECT_EQ(counter(*cl.driver, "g.errors"), 0.0);
}

// Two groups on one device: `a` reads register 0 (answered), `b` reads
// register 1 (answered with a wrong transaction id, which closes the
// connection). `a` did not even try while its device was closed: it reports
// "not connected", counted apart, never among its errors.
TEST(ModbusClientLink, NotConnectedIsNoErrorOfAGroupThatDidNotTry) {
  FakeDevice dev([](const Bytes& q) {
    Bytes r = good(q);
    if (q[9] == 1) r[1] ^= 1;  // register 1: wrong transaction id
    return r;
  });
  ModbusClientConfig cfg;
  ClientDevice d;
  d.name = "dev";
  d.port = dev.port;
  d.response_timeout_ns = 100'000'000;
  d.reconnect_min_ns = d.reconnect_max_ns = 20'000'000;
  cfg.devices.push_back(d);
  for (const char* name : {"a", "b"}) {
    RequestGroup g;
    g.name = name;
    g.function = ModbusFunction::ReadHoldingRegisters;
    g.address = name[0] == 'a' ? 0 : 1;
    g.interval_ns = 5'000'000;
    cfg.groups.push_back(g);
  }
  ModbusClientDriver driver(cfg);
  driver.set_name("io");
  std::vector<Cell> cells(driver.channels().size());
  std::vector<Cell*> ptrs;
  for (auto& c : cells) ptrs.push_back(&c);
  driver.bind(ptrs);
  std::string err;
  ASSERT_TRUE(driver.open(&err)) << err;
  EXPECT_TRUE(eventually([&] { return counter(driver, "a.not_connected") >= 3; }));
  driver.close();
  EXPECT_GE(counter(driver, "a.not_connected"), 3.0);
  EXPECT_EQ(counter(driver, "a.errors"), 0.0);  // every exchange `a` sent succeeded
  EXPECT_GE(counter(driver, "b.errors"), 3.0);
  EXPECT_EQ(counter(driver, "b.not_connected"), 0.0);
  ScanContext ctx;
  driver.latch_inputs(ctx);
  EXPECT_EQ(cells[static_cast<std::size_t>(driver.channel_index("a_errors"))].get<std::uint32_t>(), 0u);
}

// A group that writes only on change still finds out that its device died:
// it writes its unchanged values again every alive_every, so a mute device
// shows as a timeout within alive_every + response_timeout, and the group
// goes stale. Without it the group would send once and stay ok for ever.
TEST(ModbusClientLink, AnOnChangeGroupWritesAgainEveryAliveEvery) {
  std::atomic<bool> mute{false};
  FakeDevice dev([&](const Bytes& q) { return mute ? Bytes{} : q; });  // FC 6: the reply echoes the request
  ModbusClientConfig cfg;
  ClientDevice d;
  d.name = "dev";
  d.port = dev.port;
  d.response_timeout_ns = 50'000'000;
  cfg.devices.push_back(d);
  RequestGroup g;
  g.name = "w";
  g.function = ModbusFunction::WriteSingleRegister;
  g.address = 4;
  g.on_change = true;
  g.interval_ns = 2'000'000;
  g.alive_every_ns = 40'000'000;
  cfg.groups.push_back(g);
  ModbusClientDriver driver(cfg);
  driver.set_name("io");
  std::vector<Cell> cells(driver.channels().size());
  std::vector<Cell*> ptrs;
  for (auto& c : cells) ptrs.push_back(&c);
  driver.bind(ptrs);
  auto ch = [&](const char* name) -> Cell& { return cells[static_cast<std::size_t>(driver.channel_index(name))]; };
  std::string err;
  ASSERT_TRUE(driver.open(&err)) << err;
  ScanContext ctx;
  ch("w").set<std::int16_t>(7);  // the same value every scan
  // Scans every 1 ms until the group wrote 4 times (on_change alone writes
  // once); no more than one write per alive_every of the time that took
  // (every 2 ms would be 20 times as many), however long that was.
  const auto t0 = Clock::now();
  EXPECT_TRUE(eventually([&] {
    driver.latch_inputs(ctx);
    driver.write_outputs(ctx);
    return ch("w_requests").get<std::uint32_t>() >= 4;
  }));
  driver.latch_inputs(ctx);
  const double took_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  EXPECT_TRUE(ch("w_ok").get<bool>());
  const auto writes = ch("w_requests").get<std::uint32_t>();
  EXPECT_GE(writes, 4u);
  EXPECT_LE(writes, took_ms / 40.0 + 2) << "not every 2 ms: the values did not change (" << took_ms << " ms)";
  mute = true;
  EXPECT_TRUE(eventually([&] {
    driver.latch_inputs(ctx);
    driver.write_outputs(ctx);
    return !ch("w_ok").get<bool>();
  }));
  EXPECT_EQ(ch("w_error").get<std::uint16_t>(), code(ClientError::Timeout));
  driver.close();
}

// One request as a device saw it: the connection it came on (1, 2, ...),
// its function code and, for FC 6, the value written.
struct Seen {
  int connection = 0, function = 0, value = 0;
};

// Replies to FC 3 (one register), FC 6 (echo) and FC 23 (one register read)
// and logs every request; `drop` closes the connection after the next reply.
struct LoggingDevice {
  std::mutex m;
  std::vector<Seen> log;
  std::atomic<bool> drop{false};
  std::atomic<int>* connections = nullptr;
  Bytes answer(const Bytes& q) {
    Bytes r;
    if (q[7] == 6) r = q;
    else r = {q[0], q[1], 0, 0, 0, 5, q[6], q[7], 2, 0x01, 0x02};
    {
      std::lock_guard lock(m);
      log.push_back(Seen{connections->load(), q[7], static_cast<std::int16_t>((q[10] << 8) | q[11])});
    }
    if (drop.exchange(false)) r.push_back(0xEE);
    return r;
  }
  std::vector<Seen> seen() {
    std::lock_guard lock(m);
    return log;
  }
  int count(int function) {
    int n = 0;
    for (const auto& s : seen()) n += s.function == function;
    return n;
  }
};

struct GateRig {
  explicit GateRig(std::uint16_t port, std::vector<RequestGroup> groups) {
    ModbusClientConfig cfg;
    ClientDevice d;
    d.name = "dev";
    d.port = port;
    d.response_timeout_ns = 200'000'000;
    d.reconnect_min_ns = d.reconnect_max_ns = 10'000'000;
    cfg.devices.push_back(d);
    cfg.groups = std::move(groups);
    driver = std::make_unique<ModbusClientDriver>(cfg);
    driver->set_name("io");
    cells.assign(driver->channels().size(), Cell{});
    std::vector<Cell*> ptrs;
    for (auto& c : cells) ptrs.push_back(&c);
    driver->bind(ptrs);
    std::string err;
    EXPECT_TRUE(driver->open(&err)) << err;
  }
  ~GateRig() { driver->close(); }
  Cell& ch(const char* name) { return cells[static_cast<std::size_t>(driver->channel_index(name))]; }
  void scan() {
    ScanContext ctx;
    driver->latch_inputs(ctx);
    driver->write_outputs(ctx);
  }
  std::unique_ptr<ModbusClientDriver> driver;
  std::vector<Cell> cells;
};

RequestGroup group(const char* name, ModbusFunction f, std::uint16_t address) {
  RequestGroup g;
  g.name = name;
  g.function = f;
  g.address = address;
  g.interval_ns = 5'000'000;
  if (f == ModbusFunction::ReadWriteMultipleRegisters) g.write_address = 10, g.write_count = 1;
  return g;
}

// The write gate: outputs a scan handed over before the device's first good
// read on a connection (a drive block's initial controlword 0 and target 0)
// are never sent; the first write carries values computed from latched
// reads; after a reconnect the device is read again before it is written.
TEST(ModbusClientLink, NoWriteBeforeTheFirstGoodReadOnEachConnection) {
  LoggingDevice log;
  FakeDevice dev([&](const Bytes& q) { return log.answer(q); });
  log.connections = &dev.connections;
  GateRig rig(dev.port, {group("r", ModbusFunction::ReadHoldingRegisters, 0),
                         group("w", ModbusFunction::WriteSingleRegister, 4)});
  rig.ch("w").set<std::int16_t>(7);
  rig.scan();  // before any reply: the outputs of a scan that knows nothing of the device
  ASSERT_TRUE(eventually([&] { return log.count(3) >= 5; }));
  EXPECT_EQ(log.count(6), 0) << "a write went out before the scan had latched a good read";
  rig.ch("w").set<std::int16_t>(8);
  ASSERT_TRUE(eventually([&] {
    rig.scan();
    return log.count(6) >= 1;
  }));
  for (const auto& s : log.seen())
    if (s.function == 6) {
      EXPECT_EQ(s.value, 8) << "the values handed over before the first read were written";
    }
  // A reconnect: the first request on the new connection is a read.
  log.drop = true;
  ASSERT_TRUE(eventually([&] {
    rig.scan();
    for (const auto& s : log.seen())
      if (s.connection == 2 && s.function == 6) return true;
    return false;
  }));
  for (const auto& s : log.seen())
    if (s.connection == 2) {
      EXPECT_EQ(s.function, 3) << "the first request after the reconnect";
      break;
    }
  EXPECT_EQ(rig.ch("w_reconnects").get<std::uint32_t>(), 1u);
}

// A device whose only group is FC 23 (write and read in one exchange) is read
// first too: its read side alone (FC 3) until a scan latched it.
TEST(ModbusClientLink, AFunction23GroupReadsAloneUntilAScanLatchedIt) {
  LoggingDevice log;
  FakeDevice dev([&](const Bytes& q) { return log.answer(q); });
  log.connections = &dev.connections;
  GateRig rig(dev.port, {group("rw", ModbusFunction::ReadWriteMultipleRegisters, 0)});
  rig.ch("rw_write").set<std::int16_t>(5);
  ScanContext ctx;
  rig.driver->write_outputs(ctx);  // handed over, never latched
  ASSERT_TRUE(eventually([&] { return log.count(3) >= 3; }));
  EXPECT_EQ(log.count(23), 0);
  ASSERT_TRUE(eventually([&] {
    rig.scan();
    return log.count(23) >= 1;
  }));
  rig.driver->latch_inputs(ctx);
  EXPECT_EQ(rig.ch("rw").get<std::int16_t>(), 0x0102);
}

// A driver with one FC 6 group writing register 4 every 20 ms, against
// `dev`. The scans write 7; only at_stop writes the safe value.
struct StopRig {
  StopRig(std::uint16_t port, bool safe_at_stop) {
    ModbusClientConfig cfg;
    cfg.safe_at_stop = safe_at_stop;
    ClientDevice d;
    d.name = "dev";
    d.port = port;
    d.response_timeout_ns = 50'000'000;
    d.connect_timeout_ns = 50'000'000;
    cfg.devices.push_back(d);
    RequestGroup g;
    g.name = "w";
    g.function = ModbusFunction::WriteSingleRegister;
    g.address = 4;
    g.interval_ns = 20'000'000;
    cfg.groups.push_back(g);
    driver = std::make_unique<ModbusClientDriver>(cfg);
    driver->set_name("io");
    cells.assign(driver->channels().size(), Cell{});
    std::vector<Cell*> ptrs;
    for (auto& c : cells) ptrs.push_back(&c);
    driver->bind(ptrs);
    std::string err;
    EXPECT_TRUE(driver->open(&err)) << err;
  }
  // One scan writing v; waits until the device acknowledged it.
  bool write(std::int16_t v) {
    ScanContext ctx;
    cells[static_cast<std::size_t>(driver->channel_index("w"))].set<std::int16_t>(v);
    driver->write_outputs(ctx);
    return eventually([&] {
      driver->latch_inputs(ctx);
      return cells[static_cast<std::size_t>(driver->channel_index("w_ok"))].get<bool>();
    });
  }
  void stop(std::int16_t safe) {
    SafeOutput o{driver->channel_index("w"), 0, Cell{}};
    o.value.set<std::int16_t>(safe);
    driver->stop_outputs(&o, 1);
    driver->close();
  }
  std::unique_ptr<ModbusClientDriver> driver;
  std::vector<Cell> cells;
};

// A device that takes FC 6 writes and remembers the last value written.
struct Register4 {
  std::atomic<int> value{-1000};
  std::atomic<bool> mute{false};
  std::function<Bytes(const Bytes&)> answer() {
    return [this](const Bytes& q) {
      if (mute) return Bytes{};
      if (q.size() >= 12 && q[7] == 6) value = static_cast<std::int16_t>((q[10] << 8) | q[11]);
      return q;  // FC 6: the reply echoes the request
    };
  }
};

TEST(ModbusClientAtStop, SafeSendsTheSafeValuesOnceMoreAndWaitsForTheDevice) {
  Register4 reg;
  FakeDevice dev(reg.answer());
  StopRig rig(dev.port, true);
  ASSERT_TRUE(rig.write(7));
  EXPECT_EQ(reg.value.load(), 7);
  rig.stop(-3);
  EXPECT_EQ(reg.value.load(), -3);  // acknowledged before close() returned
  EXPECT_EQ(counter(*rig.driver, "w.safe_at_stop"), 1.0);
}

TEST(ModbusClientAtStop, KeepLeavesTheLastValuesInTheDevice) {
  Register4 reg;
  FakeDevice dev(reg.answer());
  StopRig rig(dev.port, false);
  ASSERT_TRUE(rig.write(7));
  rig.stop(-3);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(reg.value.load(), 7);
  for (const auto& [k, v] : rig.driver->counters()) EXPECT_NE(k, "w.safe_at_stop");
}

// A device that stopped answering: the stop waits for it (at least one
// response timeout) but not for ever — its bound, connect_timeout + 2 x
// response_timeout (150 ms here), is docs/modbus-client.md's; only a stop
// that waits for the mute device to answer reaches the hang guard — and
// says the safe values were not acknowledged.
TEST(ModbusClientAtStop, AMuteDeviceDelaysTheStopByABoundedTime) {
  Register4 reg;
  FakeDevice dev(reg.answer());
  StopRig rig(dev.port, true);
  ASSERT_TRUE(rig.write(7));
  reg.mute = true;
  const auto t0 = Clock::now();
  rig.stop(-3);
  const auto took = Clock::now() - t0;
  EXPECT_LT(took, kHangGuard) << "the stop waited for the mute device";
  EXPECT_TRUE(reg.mute.load());                    // it ended while the device was still mute
  EXPECT_GE(took, std::chrono::milliseconds(50));  // it did wait for the device
  EXPECT_EQ(counter(*rig.driver, "w.safe_at_stop"), 0.0);
}

// at_stop safe with a dead device beside a live one whose bound is long: the
// stop waits for the dead device its own bound (connect_timeout + 2 x
// response_timeout = 150 ms), not the live device's (30 s); the live one
// acknowledged its safe value.
TEST(ModbusClientAtStop, EachDeviceIsWaitedForByItsOwnBound) {
  Register4 dead, live;
  FakeDevice a(dead.answer()), b(live.answer());
  ModbusClientConfig cfg;
  cfg.safe_at_stop = true;
  for (std::uint16_t port : {a.port, b.port}) {
    ClientDevice d;
    d.name = port == a.port ? "dead" : "live";
    d.port = port;
    d.response_timeout_ns = d.connect_timeout_ns = port == a.port ? 50'000'000 : 10'000'000'000;
    cfg.devices.push_back(d);
    RequestGroup g;
    g.name = port == a.port ? "wa" : "wb";
    g.device = cfg.devices.size() - 1;
    g.function = ModbusFunction::WriteSingleRegister;
    g.address = 4;
    g.interval_ns = 20'000'000;
    cfg.groups.push_back(g);
  }
  ModbusClientDriver driver(cfg);
  driver.set_name("io");
  std::vector<Cell> cells(driver.channels().size());
  std::vector<Cell*> ptrs;
  for (auto& c : cells) ptrs.push_back(&c);
  driver.bind(ptrs);
  auto ch = [&](const char* name) -> Cell& { return cells[static_cast<std::size_t>(driver.channel_index(name))]; };
  std::string err;
  ASSERT_TRUE(driver.open(&err)) << err;
  ScanContext ctx;
  ch("wa").set<std::int16_t>(7);
  ch("wb").set<std::int16_t>(7);
  driver.write_outputs(ctx);
  ASSERT_TRUE(eventually([&] {
    driver.latch_inputs(ctx);
    return ch("wa_ok").get<bool>() && ch("wb_ok").get<bool>();
  }));
  dead.mute = true;
  std::vector<SafeOutput> safe = {SafeOutput{driver.channel_index("wa"), 0, Cell{}},
                                  SafeOutput{driver.channel_index("wb"), 0, Cell{}}};
  for (auto& o : safe) o.value.set<std::int16_t>(-3);
  const auto t0 = Clock::now();
  driver.stop_outputs(safe.data(), safe.size());
  const auto took = Clock::now() - t0;
  driver.close();
  EXPECT_EQ(live.value.load(), -3);
  EXPECT_EQ(counter(driver, "wb.safe_at_stop"), 1.0);
  EXPECT_EQ(counter(driver, "wa.safe_at_stop"), 0.0);
  EXPECT_LT(took, std::chrono::seconds(10)) << "the dead device was waited for as long as the live one's bound (30 s)";
}

// Online change of a changed driver (IoDriver::will_take_over, take_over):
// the new driver does not connect beside the old one (this fake device
// serves one connection at a time: a second would wait unanswered) but takes
// the old one's socket at the switch; the device sees one connection.
TEST(ModbusClientTakeOver, TheNewDriverTakesTheOldOnesConnection) {
  FakeDevice dev(good);
  Client old_driver(dev.port);
  ASSERT_TRUE(old_driver.wait_error(0));
  Client::Options changed;
  changed.interval_ns = 7'000'000;  // a changed setting: a new driver at an online change
  changed.open = false;
  Client next(dev.port, changed);
  next.driver->will_take_over(*old_driver.driver);
  std::string err;
  ASSERT_TRUE(next.driver->open(&err)) << err;
  std::this_thread::sleep_for(std::chrono::milliseconds(150));  // longer than a response timeout
  ScanContext ctx;
  next.driver->latch_inputs(ctx);
  EXPECT_EQ(next.ch("g_error").get<std::uint16_t>(), code(ClientError::NoReply));  // waiting, not stale
  EXPECT_EQ(next.ch("g_requests").get<std::uint32_t>(), 0u);
  next.driver->take_over(*old_driver.driver);  // the switch
  old_driver.driver->close();
  EXPECT_TRUE(next.wait_error(0));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  next.driver->latch_inputs(ctx);
  EXPECT_TRUE(next.ch("g_ok").get<bool>());
  EXPECT_EQ(next.ch("g_errors").get<std::uint32_t>(), 0u);
  EXPECT_EQ(next.ch("g_reconnects").get<std::uint32_t>(), 0u);
  EXPECT_EQ(dev.connections.load(), 1);
}

// A device of the new driver at another port is no take-over: it connects
// at open(), as a new driver does.
TEST(ModbusClientTakeOver, AnotherDeviceConnectsAtOnce) {
  FakeDevice a(good), b(good);
  Client old_driver(a.port);
  ASSERT_TRUE(old_driver.wait_error(0));
  Client::Options other;
  other.open = false;
  Client next(b.port, other);
  next.driver->will_take_over(*old_driver.driver);
  std::string err;
  ASSERT_TRUE(next.driver->open(&err)) << err;
  EXPECT_TRUE(next.wait_error(0));  // before any take_over
  next.driver->take_over(*old_driver.driver);
  old_driver.driver->close();
  EXPECT_EQ(a.connections.load(), 1);
  EXPECT_EQ(b.connections.load(), 1);
}

}  // namespace
}  // namespace syncplc
