// The Modbus server in its own thread beside real task threads, with real
// libmodbus clients: reads are never torn between scans, writes reach the
// program, many clients are served at once, a stalled client holds up
// nobody, and the program can be replaced under load. Behaviour only, never
// timing; these run under ThreadSanitizer (label "threaded").
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sched.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "runtime/core/realtime.hpp"
#include "runtime/modbus/server.hpp"
#include "runtime/core/program_change.hpp"
#include "tests/realtime/quiet_options.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using namespace std::chrono_literals;

// STAMP writes the scan time in ms to four LREALs every 200 us scan; the
// four sit in holding registers 4096..4111. A torn read would show two
// different values (or a value made of two scans' words).
const char* kProject = R"(
tasks:
  - {name: fast, period: 200us}
tags:
  - {name: stamp, type: "ARRAY[0..3] OF LREAL", address: "%ML0", hmi: read}
  - {name: sp, type: DINT, address: "%MD8", hmi: readwrite}
  - {name: sp_echo, type: DINT, address: "%MD9", hmi: read}
blocks:
  - {name: st, type: STAMP}
  - {name: e, type: MOVE, datatype: DINT}
connections:
  - st.A -> stamp[0]
  - st.B -> stamp[1]
  - st.C -> stamp[2]
  - st.D -> stamp[3]
  - sp -> e.IN
  - e.OUT -> sp_echo
)";

double lreal_of(const std::uint16_t* r) {  // high word first
  std::uint64_t u = 0;
  for (int i = 0; i < 4; ++i) u = (u << 16) | r[i];
  double d;
  std::memcpy(&d, &u, 8);
  return d;
}

struct Client {
  modbus_t* ctx = nullptr;
  explicit Client(int port) {
    ctx = modbus_new_tcp("127.0.0.1", port);
    modbus_set_response_timeout(ctx, 5, 0);
    if (modbus_connect(ctx) != 0) {
      modbus_free(ctx);
      ctx = nullptr;
    }
  }
  ~Client() {
    if (ctx) {
      modbus_close(ctx);
      modbus_free(ctx);
    }
  }
};

class ModbusServerThreads : public ::testing::Test {
 protected:
  void SetUp() override {
    program = load_test_project(kProject);
    ASSERT_TRUE(program);
    runner = std::make_unique<RealtimeRunner>(*program, quiet_options());
    runner->start();
    ModbusConfig cfg;
    cfg.enabled = true;
    cfg.port = 0;
    cfg.max_clients = 70;
    server = std::make_unique<modbus::Server>(*program, ModbusSettings{cfg, {}});
    std::string err;
    ASSERT_TRUE(server->start(&err)) << err;
  }
  void TearDown() override {
    server.reset();
    runner->request_stop();
    runner->join();
  }
  std::unique_ptr<Program> program;
  std::unique_ptr<RealtimeRunner> runner;
  std::unique_ptr<modbus::Server> server;
};

// Until done() holds; `limit` only guards against a hang.
template <class F>
bool within(std::chrono::milliseconds limit, F done) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(2ms);
  }
  return true;
}

TEST_F(ModbusServerThreads, ReadsAreNeverTornAndWritesReachTheProgram) {
  std::atomic<int> torn{0}, reads{0}, failures{0};
  std::atomic<bool> writes_done{false};
  // Each reader reads until the writes are done and it has read 100 times
  // (counted, not timed); the minute only ends a hang.
  auto reader = [&] {
    Client c(server->port());
    if (!c.ctx) { ++failures; return; }
    std::uint16_t r[16];
    const auto guard = std::chrono::steady_clock::now() + 60s;
    for (int mine = 0; (!writes_done.load() || mine < 100) && std::chrono::steady_clock::now() < guard; ++mine) {
      if (modbus_read_registers(c.ctx, 4096, 16, r) != 16) { ++failures; continue; }
      ++reads;
      const double a = lreal_of(r);
      for (int k = 1; k < 4; ++k)
        if (lreal_of(r + 4 * k) != a) ++torn;
    }
  };
  std::vector<std::thread> readers;
  for (int i = 0; i < 3; ++i) readers.emplace_back(reader);
  // Meanwhile: writes go through the queue and come back through the program.
  Client w(server->port());
  ASSERT_TRUE(w.ctx);
  for (std::int32_t v : {7, -70000, 123456789}) {
    const std::uint16_t regs[2] = {static_cast<std::uint16_t>(static_cast<std::uint32_t>(v) >> 16),
                                   static_cast<std::uint16_t>(v & 0xFFFF)};
    ASSERT_EQ(modbus_write_registers(w.ctx, 2064, 2, regs), 2);
    std::int32_t echo = 0;
    const auto guard = std::chrono::steady_clock::now() + 60s;  // only a hang
    while (echo != v && std::chrono::steady_clock::now() < guard) {
      std::uint16_t e[2];
      ASSERT_EQ(modbus_read_registers(w.ctx, 2066, 2, e), 2);
      echo = static_cast<std::int32_t>((std::uint32_t{e[0]} << 16) | e[1]);
      if (echo != v) std::this_thread::sleep_for(1ms);
    }
    EXPECT_EQ(echo, v);
    // FC 23 answers after publication: the read part already shows the echo.
    const std::uint16_t next[2] = {0, static_cast<std::uint16_t>(v & 0x7FFF)};
    std::uint16_t both[4];
    ASSERT_EQ(modbus_write_and_read_registers(w.ctx, 2064, 2, next, 2064, 4, both), 4);
    EXPECT_EQ(both[1], next[1]);
    EXPECT_EQ(both[3], next[1]) << "the program's copy, one scan later, is in the reply";
  }
  writes_done = true;
  for (auto& t : readers) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_GE(reads.load(), 300);
  EXPECT_EQ(torn.load(), 0);
}

TEST_F(ModbusServerThreads, ManyClientsAtOnceAndAStalledOneHoldsUpNobody) {
  // One connection sends half a frame and goes quiet.
  int stalled = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(server->port()));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(connect(stalled, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  const std::uint8_t half[] = {0, 1, 0, 0, 0, 6, 1, 3};
  ASSERT_EQ(send(stalled, half, sizeof half, 0), static_cast<ssize_t>(sizeof half));

  std::atomic<int> ok{0}, failed{0};
  std::vector<std::thread> clients;
  for (int i = 0; i < 64; ++i)
    clients.emplace_back([&] {
      Client c(server->port());
      if (!c.ctx) { ++failed; return; }
      std::uint16_t r[2];
      for (int k = 0; k < 20; ++k) (modbus_read_registers(c.ctx, 2066, 2, r) == 2 ? ok : failed)++;
    });
  for (auto& t : clients) t.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(ok.load(), 64 * 20);
  const auto s = server->counters().summary();
  EXPECT_EQ(s.requests, 64u * 20u);
  EXPECT_EQ(s.refused, 0u);
  close(stalled);
}

TEST_F(ModbusServerThreads, PastMaxClientsAConnectionIsClosedAtOnce) {
  std::vector<std::unique_ptr<Client>> held;
  for (int i = 0; i < 70; ++i) {
    held.push_back(std::make_unique<Client>(server->port()));
    std::uint16_t r[2];
    ASSERT_EQ(modbus_read_registers(held.back()->ctx, 2066, 2, r), 2) << i;  // served, so it holds a slot
  }
  Client extra(server->port());  // the TCP handshake completes in the kernel's backlog...
  ASSERT_TRUE(extra.ctx);
  std::uint16_t r[2];
  EXPECT_EQ(modbus_read_registers(extra.ctx, 2066, 2, r), -1) << "...but the server closes it unanswered";
  EXPECT_EQ(server->counters().summary().refused, 1u);
  held.pop_back();  // a slot frees up: the next client is served
  EXPECT_TRUE(within(60s, [&] { return server->counters().summary().open == 69; }));
  Client next(server->port());
  ASSERT_TRUE(next.ctx);
  EXPECT_EQ(modbus_read_registers(next.ctx, 2066, 2, r), 2);
}

TEST_F(ModbusServerThreads, TheProgramIsReplacedUnderLoad) {
  std::atomic<bool> stop{false};
  std::atomic<int> answered{0}, lost{0};
  std::thread client([&] {
    Client c(server->port());
    if (!c.ctx) { ++lost; return; }
    std::uint16_t r[2];
    while (!stop.load()) (modbus_read_registers(c.ctx, 2066, 2, r) == 2 ? answered : lost)++;
  });
  // Before each replacement, and after the last, the client is answered five
  // more times (counted; the minute only ends a hang).
  auto five_more = [&] {
    const int was = answered.load();
    const auto guard = std::chrono::steady_clock::now() + 60s;
    while (answered.load() < was + 5 && lost.load() == 0 && std::chrono::steady_clock::now() < guard)
      std::this_thread::sleep_for(1ms);
  };
  for (int i = 0; i < 3; ++i) {
    five_more();
    // As syncplc run's online change does: stop, load the new program, start it, swap.
    auto next = load_test_project(kProject);
    ASSERT_TRUE(next);
    runner->request_stop();
    runner->join();
    auto next_runner = std::make_unique<RealtimeRunner>(*next, quiet_options());
    next_runner->start();
    server->replace_program(*next, {});
    runner = std::move(next_runner);
    program = std::move(next);  // the old program goes only after the server let go of it
  }
  five_more();
  stop.store(true);
  client.join();
  EXPECT_EQ(lost.load(), 0);
  EXPECT_GE(answered.load(), 20);
}

}  // namespace
}  // namespace syncplc

namespace syncplc {
namespace {

TEST(ModbusServerCpus, TheThreadKeepsToItsCpusOrTheServerDoesNotStart) {
  auto program = load_test_project(kProject);
  ASSERT_TRUE(program);
  ModbusConfig cfg;
  cfg.port = 0;
  cfg.cpus = {0};
  modbus::Server on_cpu0(*program, ModbusSettings{cfg, {}});
  std::string err;
  EXPECT_TRUE(on_cpu0.start(&err)) << err;
  on_cpu0.stop();
  cfg.cpus = {1023};  // no such CPU here
  modbus::Server nowhere(*program, ModbusSettings{cfg, {}});
  EXPECT_FALSE(nowhere.start(&err));
  EXPECT_EQ(err, "cannot keep the server thread to CPU 1023: Invalid argument");
}

// The CPUs the server thread ("modbus") may run on, from /proc.
std::string modbus_thread_cpus() {
  for (const auto& t : std::filesystem::directory_iterator("/proc/self/task")) {
    std::ifstream comm(t.path() / "comm");
    std::string name;
    std::getline(comm, name);
    if (name != "modbus") continue;
    std::ifstream status(t.path() / "status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("Cpus_allowed_list:", 0) == 0) return line.substr(line.find_first_not_of(" \t", 18));
  }
  return "no modbus thread";
}

TEST(ModbusServerCpus, WithoutCpusTheThreadKeepsOffPinnedTasksCpus) {
  cpu_set_t all;
  ASSERT_EQ(sched_getaffinity(0, sizeof all, &all), 0);
  if (!CPU_ISSET(0, &all) || !CPU_ISSET(1, &all)) GTEST_SKIP() << "needs CPUs 0 and 1";
  std::string others;  // every CPU this process may use but 0
  for (int c = 1; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &all)) others += (others.empty() ? "" : ",") + std::to_string(c);
  std::string everything = "0," + others;
  auto compact = [](std::string list) {  // "1,2,3" as /proc writes it: "1-3"
    std::vector<int> v;
    for (std::size_t at = 0; at < list.size();) {
      const std::size_t end = list.find(',', at);
      v.push_back(std::stoi(list.substr(at, end - at)));
      at = end == std::string::npos ? list.size() : end + 1;
    }
    std::string out;
    for (std::size_t i = 0; i < v.size();) {
      std::size_t j = i;
      while (j + 1 < v.size() && v[j + 1] == v[j] + 1) ++j;
      out += (out.empty() ? "" : ",") + std::to_string(v[i]) + (j > i ? "-" + std::to_string(v[j]) : "");
      i = j + 1;
    }
    return out;
  };
  std::string project = kProject;
  const std::string task_line = "  - {name: fast, period: 200us}";
  project.replace(project.find(task_line), task_line.size(), "  - {name: fast, period: 200us, cpu: 0}");
  auto pinned = load_test_project(project);
  auto free = load_test_project(kProject);
  ASSERT_TRUE(pinned && free);
  ModbusConfig cfg;
  cfg.port = 0;
  std::string err;
  {
    modbus::Server server(*pinned, ModbusSettings{cfg, {}});
    ASSERT_TRUE(server.start(&err)) << err;
    EXPECT_TRUE(server.off_task_cpus());
    EXPECT_EQ(modbus_thread_cpus(), compact(others)) << "off CPU 0, where task fast runs";
    server.replace_program(*free, {});  // an online change to a program that pins nothing
    EXPECT_FALSE(server.off_task_cpus());
    EXPECT_EQ(modbus_thread_cpus(), compact(everything));
    server.replace_program(*pinned, {});
    EXPECT_EQ(modbus_thread_cpus(), compact(others));
  }
  {
    cfg.cpus = {0};  // set by hand: the setting wins, even on a pinned task's CPU
    modbus::Server server(*pinned, ModbusSettings{cfg, {}});
    ASSERT_TRUE(server.start(&err)) << err;
    EXPECT_FALSE(server.off_task_cpus());
    EXPECT_EQ(modbus_thread_cpus(), "0");
  }
}

// A task so slow that a write and read (FC 23) to it waits for seconds: what
// the server does with the connection meanwhile. No task thread runs here;
// the program's first snapshot is its initial values.
const char* kSlowProject = R"(
tasks:
  - {name: slow, period: 10s}
tags:
  - {name: a, type: INT, address: "%MW0", hmi: readwrite, init: 5}
  - {name: b, type: INT, address: "%MW1", hmi: readwrite, init: 6}
)";

int connect_raw(int port) {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    close(s);
    return -1;
  }
  timeval tv{5, 0};
  setsockopt(s, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  return s;
}

// One reply (MBAP header and PDU), or empty on timeout or close.
bool readable_within(int s, std::chrono::milliseconds limit) {
  pollfd p{s, POLLIN, 0};
  return poll(&p, 1, static_cast<int>(limit.count())) > 0;
}

std::vector<std::uint8_t> recv_reply(int s) {
  std::vector<std::uint8_t> out(7);
  std::size_t got = 0;
  auto fill = [&](std::size_t want) {
    while (got < want) {
      const ssize_t n = recv(s, out.data() + got, want - got, 0);
      if (n <= 0) return false;
      got += static_cast<std::size_t>(n);
    }
    return true;
  };
  if (!fill(7)) return {};
  out.resize(6 + ((out[4] << 8) | out[5]));
  if (!fill(out.size())) return {};
  return out;
}


// FC 23: write b := 9, read a..b; then FC 3 of a..b, pipelined behind it.
const std::uint8_t kWriteRead[] = {0, 1, 0, 0, 0, 13, 1, 0x17, 0x04, 0x00, 0, 2, 0x04, 0x01, 0, 1, 2, 0, 9};
const std::uint8_t kRead[] = {0, 2, 0, 0, 0, 6, 1, 0x03, 0x04, 0x00, 0, 2};

class ModbusServerWaiting : public ::testing::Test {
 protected:
  void SetUp() override {
    program = load_test_project(kSlowProject);
    ASSERT_TRUE(program);
    ModbusConfig cfg;
    cfg.port = 0;
    server = std::make_unique<modbus::Server>(*program, ModbusSettings{cfg, {}});
    std::string err;
    ASSERT_TRUE(server->start(&err)) << err;
  }
  std::unique_ptr<Program> program;
  std::unique_ptr<modbus::Server> server;
};

TEST_F(ModbusServerWaiting, AClientThatResetsWhileItsWriteAndReadWaitsIsClosedAtOnce) {
  const int s = connect_raw(server->port());
  ASSERT_GE(s, 0);
  ASSERT_EQ(send(s, kWriteRead, sizeof kWriteRead, 0), static_cast<ssize_t>(sizeof kWriteRead));
  ASSERT_TRUE(within(60s, [&] { return server->counters().summary().requests == 1; }));
  const linger reset{1, 0};  // close with RST
  setsockopt(s, SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
  close(s);
  // Its reply would wait 2 s + 3 periods (32 s); epoll reports the reset all
  // that time, so the connection must go now (or the loop spins).
  EXPECT_TRUE(within(60s, [&] { return server->counters().summary().open == 0; }));
  EXPECT_EQ(server->counters().summary().closed_by_peer, 1u);
  // And the server goes on serving.
  const int t = connect_raw(server->port());
  ASSERT_EQ(send(t, kRead, sizeof kRead, 0), static_cast<ssize_t>(sizeof kRead));
  EXPECT_EQ(recv_reply(t), (std::vector<std::uint8_t>{0, 2, 0, 0, 0, 7, 1, 0x03, 4, 0, 5, 0, 6}));
  close(t);
}

TEST_F(ModbusServerWaiting, AtAProgramChangeAWaitingWriteAndReadIsAnsweredAndWhatFollowsItServed) {
  auto next = load_test_project(kSlowProject);
  ASSERT_TRUE(next);
  const int s = connect_raw(server->port());
  ASSERT_GE(s, 0);
  std::vector<std::uint8_t> both(kWriteRead, kWriteRead + sizeof kWriteRead);
  both.insert(both.end(), kRead, kRead + sizeof kRead);
  ASSERT_EQ(send(s, both.data(), both.size(), 0), static_cast<ssize_t>(both.size()));
  ASSERT_TRUE(within(60s, [&] { return server->counters().summary().requests == 1; })) << "FC 23 read, FC 3 behind it";
  // As syncplc run does at an online change: hold, plan, let the old tasks
  // mirror into the new program, serve the new program. The waiting write
  // and read now waits for two publications of the new task, which the old
  // task makes (it applies the queue and mirrors).
  server->hold();
  auto change = plan_change(*program, *next);  // carries the tags over
  change->switch_ns = 1'000'000'000'000;
  begin_mirroring(*change);
  server->replace_program(*next, {});
  EXPECT_FALSE(readable_within(s, 300ms)) << "answered before its write was published";
  for (int k = 0; k < 2; ++k) {
    ScanContext ctx;
    ctx.now_ns = 10'000'000'000LL * (k + 1);
    program->tasks[0]->scan(ctx);
    program->tasks[0]->publish();
  }
  EXPECT_EQ(recv_reply(s), (std::vector<std::uint8_t>{0, 1, 0, 0, 0, 7, 1, 0x17, 4, 0, 5, 0, 9}))
      << "the write and read, from the new program: b = 9 carried over";
  EXPECT_EQ(recv_reply(s), (std::vector<std::uint8_t>{0, 2, 0, 0, 0, 7, 1, 0x03, 4, 0, 5, 0, 9}))
      << "the read that waited behind it";
  close(s);
}

}  // namespace
}  // namespace syncplc
