// The request handler answers over a socket pair, with the program run in
// virtual time: what each function code returns, every exception in the
// protocol's order of checks, and when writes reach the program.
#include <fcntl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/modbus/request_handler.hpp"
#include "tests/modbus/handler_project.hpp"
#include "tests/modbus/modbus_frames.hpp"
#include "tests/support/project_fixture.hpp"

namespace syncplc {
namespace {

using namespace syncplc::modbus;
using testing::Bytes;
using testing::frame;
using testing::pdu;


class Handler : public ::testing::Test {
 protected:
  void SetUp() override {
    auto loaded = load_test_result(testing::kHandlerProject);
    program = std::move(loaded.program);
    places = loaded.modbus.places;
    ASSERT_TRUE(program);
    clock = std::make_unique<VirtualClock>(*program);
    ASSERT_EQ(socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    fcntl(fds[1], F_SETFL, O_NONBLOCK);
    make_handler();
    scan_until(2'000'000);  // every task has published its initial values
  }
  void TearDown() override {
    close(fds[0]);
    close(fds[1]);
  }
  void make_handler() {
    handler = std::make_unique<RequestHandler>(config, counters);
    handler->set_program(*program, places);
  }
  void scan_until(std::int64_t t) {
    clock->run_until(t, true);
    now = t;
  }
  // Sends one request and returns the whole reply (MBAP header included).
  Bytes ask(const Bytes& request, RequestHandler::Outcome expect = RequestHandler::Outcome::Sent) {
    EXPECT_EQ(handler->handle(fds[0], request.data(), request.size(), pending, now), expect);
    return answer();
  }
  Bytes answer() {
    Bytes out(300);
    const ssize_t n = read(fds[1], out.data(), out.size());
    out.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    return out;
  }
  // The PDU of a reply (function code onward), after checking its header.
  static Bytes body(const Bytes& reply) {
    if (reply.size() < 8) return {};
    EXPECT_EQ(reply[0], 0x12);
    EXPECT_EQ(reply[1], 0x34) << "transaction id echoed";
    EXPECT_EQ(reply[2] | reply[3], 0) << "protocol id";
    EXPECT_EQ(static_cast<std::size_t>((reply[4] << 8) | reply[5]), reply.size() - 6) << "length field";
    return Bytes(reply.begin() + 7, reply.end());
  }
  static Bytes exception_of(std::uint8_t fc, std::uint8_t code) { return Bytes{static_cast<std::uint8_t>(fc | 0x80), code}; }

  ModbusConfig config;
  Counters counters;
  std::unique_ptr<Program> program;
  ModbusPlaces places;  // the project's explicit places (small, octet, trim)
  std::unique_ptr<VirtualClock> clock;
  std::unique_ptr<RequestHandler> handler;
  PendingReply pending;
  std::int64_t now = 0;
  int fds[2] = {-1, -1};
};

TEST_F(Handler, ReadsEveryTable) {
  // Coils 0..11: run FALSE, lamps TRUE x10, then %QX1.3.. unmapped -> only 0..10 mapped.
  EXPECT_EQ(body(ask(frame(pdu(0x01, 0, 11)))), (Bytes{0x01, 2, 0xFE, 0x07}));
  EXPECT_EQ(body(ask(frame(pdu(0x01, 16, 1)))), (Bytes{0x01, 1, 0x01})) << "fault: %QX2.0 = coil 16";
  EXPECT_EQ(body(ask(frame(pdu(0x02, 0, 1)))), (Bytes{0x02, 1, 0x01}));
  EXPECT_EQ(body(ask(frame(pdu(0x04, 7, 1)))), (Bytes{0x04, 2, 0xFF, 0xFE}));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 2)))), (Bytes{0x03, 4, 0x00, 0x07, 0x00, 0x07})) << "sp and its echo";
  // REAL 1.0 high word first, then its echo, then DINT -2.
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2048, 6)))),
            (Bytes{0x03, 12, 0x3F, 0x80, 0, 0, 0x3F, 0x80, 0, 0, 0xFF, 0xFF, 0xFF, 0xFE}));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 4104, 4)))), (Bytes{0x03, 8, 0x3F, 0xF8, 0, 0, 0, 0, 0, 0})) << "LREAL 1.5";
  EXPECT_EQ(counters.requests.load(), 7u);
  EXPECT_EQ(counters.exceptions.load(), 0u);
}

TEST_F(Handler, LowWordFirstSwapsTheWordsOfEveryWideValue) {
  config.word_order = WordOrder::LowFirst;
  make_handler();
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2048, 2)))), (Bytes{0x03, 4, 0, 0, 0x3F, 0x80}));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 4104, 4)))), (Bytes{0x03, 8, 0, 0, 0, 0, 0, 0, 0x3F, 0xF8}));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2052, 2)))), (Bytes{0x03, 4, 0xFF, 0xFE, 0xFF, 0xFF}));
  // A write in that order lands as the same value.
  ask(frame(testing::write_registers(2048, {0x0000, 0x4049})));  // 3.140625 = 0x40490000
  scan_until(3'000'000);
  EXPECT_EQ(tag_cell(*program, "pos").get<float>(), 3.140625f);
}

TEST_F(Handler, WritesLandAtTheNextScanOfTheirTaskInArrivalOrder) {
  const Bytes w1 = frame(pdu(0x06, 2, 100));
  EXPECT_EQ(body(ask(w1)), Bytes(w1.begin() + 7, w1.end())) << "FC 6 echoes the request";
  ask(frame(pdu(0x06, 2, 200)));  // the later write wins: applied in arrival order
  EXPECT_EQ(tag_cell(*program, "sp").get<std::int16_t>(), 7) << "nothing touches the image before the scan";
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 1)))), (Bytes{0x03, 2, 0, 7})) << "reads show the last published scan";
  scan_until(2'000'000 + 1);  // the 2 ms scan of main has run, not yet published
  scan_until(3'000'000);
  EXPECT_EQ(tag_cell(*program, "sp").get<std::int16_t>(), 200);
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 2)))), (Bytes{0x03, 4, 0, 200, 0, 200})) << "the program saw it";
  // FC 5 and FC 15.
  EXPECT_EQ(body(ask(frame(pdu(0x05, 0, 0xFF00)))), (Bytes{0x05, 0, 0, 0xFF, 0}));
  EXPECT_EQ(body(ask(frame(testing::write_coils(1, {false, true, false})))), (Bytes{0x0F, 0, 1, 0, 3}));
  scan_until(4'000'000);
  EXPECT_TRUE(tag_cell(*program, "run").get<bool>());
  EXPECT_EQ(body(ask(frame(pdu(0x01, 0, 4)))), (Bytes{0x01, 1, 0b0101}));
  // A request spanning two tasks: each gets its part at its own next scan.
  ask(frame(testing::write_registers(4104, {0x4000, 0, 0, 0, 0, 0, 0, 1000})));  // big = 2.0, when = 1000 ns
  scan_until(10'000'000 - 1);
  EXPECT_EQ(tag_cell(*program, "big").get<double>(), 1.5) << "slow's next scan is at 10 ms";
  scan_until(10'000'000);
  EXPECT_EQ(tag_cell(*program, "big").get<double>(), 2.0);
  EXPECT_EQ(tag_cell(*program, "when").get<std::int64_t>(), 1000);
  EXPECT_EQ(counters.values_written.load(), 8u) << "2 + 1 + 3 + 2";
}

TEST_F(Handler, AnswersEveryExceptionInTheProtocolsOrder) {
  struct Case {
    const char* what;
    Bytes request;
    std::uint8_t code;
  };
  const std::vector<Case> cases = {
      {"unknown function", frame(pdu(0x07, 0, 0)), 0x01},
      {"encapsulated interface", frame(Bytes{0x2B, 0x0E, 1, 0}), 0x01},
      {"an exception code as function", frame(pdu(0x83, 0, 1)), 0x01},
      {"quantity 0 before address", frame(pdu(0x03, 60000, 0)), 0x03},
      {"126 registers", frame(pdu(0x03, 0, 126)), 0x03},
      {"2001 coils", frame(pdu(0x01, 0, 2001)), 0x03},
      {"a read with a trailing byte", frame(Bytes{0x03, 0, 0, 0, 1, 0}), 0x03},
      {"a short read", frame(Bytes{0x03, 0, 0}), 0x03},
      {"byte count not 2 x quantity", frame(Bytes{0x10, 0, 0, 0, 1, 3, 0, 1, 2}), 0x03},
      {"byte count beyond the frame", frame(Bytes{0x10, 0, 0, 0, 2, 4, 0, 1}), 0x03},
      {"coil bytes short", frame(Bytes{0x0F, 0, 0, 0, 9, 1, 0xFF}), 0x03},
      {"single coil value 0x1234", frame(pdu(0x05, 0, 0x1234)), 0x03},
      {"unmapped register", frame(pdu(0x03, 500, 1)), 0x02},
      {"range runs into unmapped", frame(pdu(0x03, 2, 5)), 0x02},
      {"cuts a REAL", frame(pdu(0x03, 2049, 1)), 0x02},
      {"range ends inside an LREAL", frame(pdu(0x03, 4104, 3)), 0x02},
      {"no wrap past 65535", frame(pdu(0x03, 65535, 2)), 0x02},
      {"write to a read-only tag", frame(pdu(0x06, 3, 5)), 0x02},
      {"write to a read-only coil", frame(pdu(0x05, 16, 0xFF00)), 0x02},
      {"single-register write into a REAL", frame(pdu(0x06, 2048, 5)), 0x02},
      {"input registers are not holding", frame(pdu(0x06, 7, 5)), 0x02},
      {"REAL NaN", frame(testing::write_registers(2048, {0x7FC0, 0})), 0x03},
      {"REAL infinity", frame(testing::write_registers(2048, {0x7F80, 0})), 0x03},
      {"SINT 128", frame(pdu(0x06, 100, 128)), 0x03},
      {"SINT -129", frame(pdu(0x06, 100, 0xFF7F)), 0x03},
      {"BYTE 256", frame(testing::write_registers(100, {0, 256})), 0x03},
      {"INT above its tag's max", frame(pdu(0x06, 2, 1001)), 0x03},
      {"INT below its tag's min, in a multiple write", frame(testing::write_registers(2, {0xFC17})), 0x03},  // -1001
      {"unit 7", frame(pdu(0x03, 2, 1), 7), 0x0B},
  };
  std::uint64_t by_code[12] = {};
  for (const auto& c : cases) {
    EXPECT_EQ(body(ask(c.request)), exception_of(c.request[7], c.code)) << c.what;
    ++by_code[c.code];
  }
  for (int code : {1, 2, 3, 0x0B}) EXPECT_EQ(counters.by_exception[static_cast<std::size_t>(code)].load(), by_code[code]) << code;
  EXPECT_EQ(counters.exceptions.load(), cases.size());
  EXPECT_EQ(counters.values_written.load(), 0u) << "no failed request queued anything";
  // SINT -128 and BYTE 255 are in range; unit 0 and 255 are always answered.
  EXPECT_EQ(body(ask(frame(testing::write_registers(100, {0xFF80, 255}))))[0], 0x10);
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 1), 0)))[0], 0x03);
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 1), 255)))[0], 0x03);
  scan_until(3'000'000);
  EXPECT_EQ(tag_cell(*program, "small").get<std::int8_t>(), -128);
  EXPECT_EQ(tag_cell(*program, "octet").get<std::uint8_t>(), 255);
  EXPECT_EQ(body(ask(frame(pdu(0x03, 100, 2)))), (Bytes{0x03, 4, 0xFF, 0x80, 0, 255})) << "SINT sign-extended";
}

TEST_F(Handler, AReadOnlyServerRefusesEveryWriteWithException02) {
  config.read_only = true;
  make_handler();
  EXPECT_EQ(body(ask(frame(pdu(0x06, 2, 1)))), exception_of(0x06, 0x02));
  EXPECT_EQ(body(ask(frame(pdu(0x05, 0, 0xFF00)))), exception_of(0x05, 0x02));
  EXPECT_EQ(body(ask(frame(testing::write_registers(2, {1})))), exception_of(0x10, 0x02));
  EXPECT_EQ(body(ask(frame(testing::write_coils(0, {true})))), exception_of(0x0F, 0x02));
  EXPECT_EQ(body(ask(frame(testing::write_read(2, 1, 2, {1})))), exception_of(0x17, 0x02));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 1))))[0], 0x03) << "reads still work";
}

TEST_F(Handler, AFullWriteQueueIsException06AndQueuesNothingMore) {
  // slow's queue holds 16 values; each LREAL write is one value.
  int accepted = 0;
  for (int i = 0; i < 20; ++i) {
    Bytes r = body(ask(frame(testing::write_registers(4104, {0x4000, 0, 0, 0}))));
    if (r[0] == 0x10) ++accepted;
    else EXPECT_EQ(r, exception_of(0x10, 0x06));
  }
  EXPECT_EQ(accepted, 16);
  EXPECT_EQ(counters.by_exception[6].load(), 4u);
  scan_until(10'000'000);
  EXPECT_EQ(body(ask(frame(testing::write_registers(4104, {0x4000, 0, 0, 0}))))[0], 0x10) << "room again after the scan";
}

TEST_F(Handler, WriteAndReadAnswersOnceTheWriteIsPublished) {
  // Write sp := 55 and read sp and its echo: the reply waits for the scan that applies
  // the write and the scan after it (the echo is computed in the applying scan).
  const Bytes request = frame(testing::write_read(2, 2, 2, {55}));
  ask(request, RequestHandler::Outcome::Deferred);
  EXPECT_TRUE(pending.active);
  EXPECT_TRUE(answer().empty()) << "no reply before the write is published";
  EXPECT_FALSE(handler->ready(pending, now));
  std::int64_t t = now;
  while (!handler->ready(pending, t)) {
    t += 1'000'000;
    scan_until(t);
    ASSERT_LT(t, 10'000'000) << "never published";
  }
  EXPECT_LE(t, 4'000'000) << "two publications of main, 1 ms apart";
  EXPECT_EQ(handler->finish(fds[0], pending, t), RequestHandler::Outcome::Sent);
  EXPECT_EQ(body(answer()), (Bytes{0x17, 4, 0, 55, 0, 55}));
  // A stopped task never publishes: the reply is exception 04 at the deadline.
  ask(frame(testing::write_read(2, 1, 2, {66})), RequestHandler::Outcome::Deferred);
  EXPECT_FALSE(handler->ready(pending, t + 1'000'000'000));
  EXPECT_TRUE(handler->ready(pending, pending.deadline_ns));
  EXPECT_EQ(handler->finish(fds[0], pending, pending.deadline_ns), RequestHandler::Outcome::Sent);
  EXPECT_EQ(body(answer()), exception_of(0x17, 0x04));
}

TEST_F(Handler, AWriteSpanningTwoTasksIsQueuedWholeOrNotAtAll) {
  // Fill slow's queue (16 values), then write trim (main) and big (slow) in one request.
  for (int i = 0; i < 16; ++i) ASSERT_EQ(body(ask(frame(testing::write_registers(4104, {0x4000, 0, 0, 0}))))[0], 0x10);
  const Bytes both = frame(testing::write_registers(4100, {0x4008, 0, 0, 0, 0x4010, 0, 0, 0}));  // trim 3.0, big 4.0
  EXPECT_EQ(body(ask(both)), exception_of(0x10, 0x06));
  EXPECT_EQ(counters.values_written.load(), 16u) << "nothing of the refused request was counted";
  scan_until(3'000'000);
  EXPECT_EQ(tag_cell(*program, "trim").get<double>(), 0.0) << "main's part was not queued either";
  scan_until(10'000'000);  // slow's scan empties its queue
  EXPECT_EQ(body(ask(both))[0], 0x10);
  scan_until(20'000'000);
  EXPECT_EQ(tag_cell(*program, "trim").get<double>(), 3.0);
  EXPECT_EQ(tag_cell(*program, "big").get<double>(), 4.0);
}

TEST_F(Handler, EveryWriteToAStoppedTaskIsException04AndQueuesNothing) {
  // main stops (as the supervisor stops a task whose scan does not end; a
  // watchdog stop sets the same flag). The virtual clock goes on scanning it,
  // so anything queued would show.
  program->tasks[0]->stop_from_supervisor();
  const std::uint64_t written = counters.values_written.load();
  EXPECT_EQ(body(ask(frame(pdu(0x05, 0, 0xFF00)))), exception_of(0x05, 0x04));
  EXPECT_EQ(body(ask(frame(pdu(0x06, 2, 100)))), exception_of(0x06, 0x04));
  EXPECT_EQ(body(ask(frame(testing::write_coils(1, {false, true, false})))), exception_of(0x0F, 0x04));
  EXPECT_EQ(body(ask(frame(testing::write_registers(2, {300})))), exception_of(0x10, 0x04));
  EXPECT_EQ(body(ask(frame(testing::write_read(2, 1, 2, {400})))), exception_of(0x17, 0x04)) << "not deferred";
  EXPECT_FALSE(pending.active);
  // The address and value checks still come first (02, 03), and reads are served.
  EXPECT_EQ(body(ask(frame(pdu(0x06, 3, 1)))), exception_of(0x06, 0x02)) << "sp_echo is read-only";
  EXPECT_EQ(body(ask(frame(pdu(0x06, 100, 200)))), exception_of(0x06, 0x03)) << "200 is no SINT";
  EXPECT_EQ(body(ask(frame(pdu(0x03, 2, 1)))), (Bytes{0x03, 2, 0, 7}));
  scan_until(5'000'000);
  EXPECT_FALSE(tag_cell(*program, "run").get<bool>());
  EXPECT_EQ(tag_cell(*program, "sp").get<std::int16_t>(), 7);
  EXPECT_TRUE(tag_cell(*program, "lamps[1]").get<bool>());
  EXPECT_EQ(counters.values_written.load(), written);
  EXPECT_EQ(counters.by_exception[4].load(), 5u);
}

TEST_F(Handler, AWriteSpanningARunningAndAStoppedTaskIsRefusedWhole) {
  program->tasks[1]->stop_from_supervisor();  // slow
  const Bytes both = frame(testing::write_registers(4100, {0x4008, 0, 0, 0, 0x4010, 0, 0, 0}));  // trim 3.0, big 4.0
  EXPECT_EQ(body(ask(both)), exception_of(0x10, 0x04));
  EXPECT_EQ(body(ask(frame(testing::write_registers(4100, {0x4008, 0, 0, 0})))), (Bytes{0x10, 0x10, 0x04, 0, 4}))
      << "main's tag alone is written";
  scan_until(5'000'000);
  EXPECT_EQ(tag_cell(*program, "trim").get<double>(), 3.0);
  EXPECT_EQ(counters.values_written.load(), 1u) << "main's part of the refused request was not queued";
}

TEST_F(Handler, AWriteAndReadWhoseTaskStopsWhileItWaitsIsAnswered04AtOnce) {
  ask(frame(testing::write_read(2, 1, 2, {66})), RequestHandler::Outcome::Deferred);
  EXPECT_FALSE(handler->ready(pending, now));
  program->tasks[0]->stop_from_supervisor();
  EXPECT_TRUE(handler->ready(pending, now)) << "long before the deadline";
  EXPECT_EQ(handler->finish(fds[0], pending, now), RequestHandler::Outcome::Sent);
  EXPECT_EQ(body(answer()), exception_of(0x17, 0x04));
}

TEST_F(Handler, WriteAndReadShowsWhatTheProgramMadeOfTheWrite) {
  // The read part of FC 23 is the program's published image after the scan
  // that applied the write: sp_echo, which a MOVE copies from sp in that
  // scan, shows the 5 the client wrote to sp, and forced the program's 42.
  ask(frame(testing::write_read(3, 2, 2, {5})), RequestHandler::Outcome::Deferred);
  std::int64_t t = now;
  while (!handler->ready(pending, t)) scan_until(t += 1'000'000);
  EXPECT_EQ(handler->finish(fds[0], pending, t), RequestHandler::Outcome::Sent);
  EXPECT_EQ(body(answer()), (Bytes{0x17, 4, 0, 5, 0, 42}));
  EXPECT_EQ(body(ask(frame(pdu(0x03, 3, 2)))), (Bytes{0x03, 4, 0, 5, 0, 42})) << "as FC 3 shows it";
  // Where the program leaves the written value alone, the reply shows it (sp and its echo).
  ask(frame(testing::write_read(2, 2, 2, {9})), RequestHandler::Outcome::Deferred);
  while (!handler->ready(pending, t)) scan_until(t += 1'000'000);
  EXPECT_EQ(handler->finish(fds[0], pending, t), RequestHandler::Outcome::Sent);
  EXPECT_EQ(answer(), (Bytes{0x12, 0x34, 0, 0, 0, 7, 1, 0x17, 4, 0, 9, 0, 9})) << "the whole frame, header included";
}

TEST(HandlerQueues, TheLargestWriteOfTheProtocolFitsTheDefaultQueue) {
  // 2000 writable coils in one task: FC 15 may carry 1968 of them at once, more
  // than the default queue of 1024, which therefore grows at load.
  auto program = load_test_project(R"(
tasks:
  - {name: main, period: 1ms}
tags:
  - {name: valves, type: "ARRAY[0..1999] OF BOOL", address: "%QX0.0", hmi: readwrite}
)");
  ASSERT_TRUE(program);
  EXPECT_GE(program->tasks[0]->config().write_queue, 1968u);
  VirtualClock clock(*program);
  clock.run_until(1'000'000, true);
  ModbusConfig config;
  Counters counters;
  RequestHandler handler(config, counters);
  handler.set_program(*program);
  int fds[2];
  ASSERT_EQ(socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  Bytes coils;
  coils.push_back(0x0F);
  testing::put16(coils, 0);
  testing::put16(coils, 1968);
  coils.push_back(1968 / 8);
  for (int i = 0; i < 1968 / 8; ++i) coils.push_back(0xFF);
  const Bytes request = frame(coils);
  PendingReply pending;
  EXPECT_EQ(handler.handle(fds[0], request.data(), request.size(), pending, 1'000'000), RequestHandler::Outcome::Sent);
  std::uint8_t reply[16];
  ASSERT_EQ(read(fds[1], reply, sizeof reply), 12);
  EXPECT_EQ(reply[7], 0x0F) << "not exception 06";
  clock.run_until(2'000'000, true);
  std::vector<Cell> v(2000);
  program->read_tag(*program->find_tag("valves"), v.data());
  EXPECT_TRUE(v[0].get<bool>() && v[1967].get<bool>() && !v[1968].get<bool>());
  close(fds[0]);
  close(fds[1]);
}

TEST_F(Handler, ASocketThatTakesNothingFailsTheSendInsteadOfBlocking) {
  // Fill the peer's receive side: a client that stopped reading.
  fcntl(fds[0], F_SETFL, O_NONBLOCK);
  const Bytes request = frame(pdu(0x03, 2048, 6));
  RequestHandler::Outcome last = RequestHandler::Outcome::Sent;
  int sent = 0;
  while (last == RequestHandler::Outcome::Sent && sent < 1'000'000) {
    last = handler->handle(fds[0], request.data(), request.size(), pending, now);
    ++sent;
  }
  EXPECT_EQ(last, RequestHandler::Outcome::SendFailed);
  EXPECT_GT(sent, 10);
}

TEST(Frame, JudgesTheHeaderAsItArrives) {
  const Bytes f = frame(pdu(0x03, 0, 1));
  for (std::size_t n = 0; n < f.size(); ++n) EXPECT_EQ(check_frame(f.data(), n).status, FrameStatus::Incomplete) << n;
  auto whole = check_frame(f.data(), f.size());
  EXPECT_EQ(whole.status, FrameStatus::Complete);
  EXPECT_EQ(whole.length, 12u);
  // Two pipelined frames: the first is whole.
  Bytes two = f;
  two.insert(two.end(), f.begin(), f.end());
  EXPECT_EQ(check_frame(two.data(), two.size()).length, 12u);
  const Bytes http = {'G', 'E', 'T', ' ', '/', ' '};
  EXPECT_EQ(check_frame(http.data(), 4).status, FrameStatus::Bad) << "refused at the protocol id";
  EXPECT_EQ(check_frame(http.data(), 4).reason, "protocol id 21536 is not 0 (Modbus)");
  Bytes longest = {0, 1, 0, 0, 0, 254};
  EXPECT_EQ(check_frame(longest.data(), 6).status, FrameStatus::Incomplete);
  Bytes too_long = {0, 1, 0, 0, 0, 255};
  EXPECT_EQ(check_frame(too_long.data(), 6).reason, "length field 255 outside 2..254");
  Bytes too_short = {0, 1, 0, 0, 0, 1, 1};
  EXPECT_EQ(check_frame(too_short.data(), 7).status, FrameStatus::Bad);
}

// Input registers 9000.. (the default task_status): eight per task, main then slow.
TEST_F(Handler, TaskStatusRegistersTellStateAgeScansAndPeriod) {
  // Virtual time here (no epoch): the age reads 0; the real-time side sets it.
  scan_until(20'000'000);  // main: releases 0..20 ms = 21 scans; slow: 0, 10, 20 ms = 3
  Bytes r = body(ask(frame(pdu(0x04, 9000, 16))));
  ASSERT_EQ(r.size(), 2u + 32u);
  auto reg = [&](int i) { return static_cast<std::uint16_t>((r[2 + 2 * i] << 8) | r[3 + 2 * i]); };
  EXPECT_EQ(reg(0), 1) << "main running";
  EXPECT_EQ(reg(0 + 5), 21) << "main's scans (ULINT, high word first: low word last)";
  EXPECT_EQ(reg(0 + 7), 1000) << "main's period in us (UDINT, low word)";
  EXPECT_EQ(reg(8), 1) << "slow running";
  EXPECT_EQ(reg(8 + 5), 3);
  EXPECT_EQ(reg(8 + 7), 10000);
  // A stopped task: its values are stale, and its state says so.
  program->tasks[1]->stop_from_supervisor();
  r = body(ask(frame(pdu(0x04, 9008, 1))));
  EXPECT_EQ(r, (Bytes{0x04, 2, 0, 2})) << "slow stopped";
  // The age on the real-time axis: with the epoch 25 ms ago, slow's newest values (released at 20 ms) are 5 ms old.
  const std::int64_t e0 = monotonic_ns();
  program->epoch_ns.store(e0 - 25'000'000);
  r = body(ask(frame(pdu(0x04, 9009, 1))));
  const std::int64_t asked_ms = (monotonic_ns() - e0) / 1'000'000;
  ASSERT_EQ(r.size(), 4u);
  const int age = (r[2] << 8) | r[3];
  EXPECT_GE(age, 5);
  EXPECT_LE(age, 5 + asked_ms + 1) << "5 ms and the " << asked_ms << " ms the request took";
  // The block cannot be cut (a ULINT is four registers) and is read-only.
  EXPECT_EQ(body(ask(frame(pdu(0x04, 9003, 1)))), exception_of(0x04, 0x02));
}

// Input registers 8990.. (the default store_status): the store's state as its source tells it.
TEST_F(Handler, StoreStatusRegistersTellStatePendingDroppedFailures) {
  Bytes r = body(ask(frame(pdu(0x04, 8990, 8))));
  EXPECT_EQ(r, (Bytes{0x04, 16, 0, 2, 0xFF, 0xFF, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0})) << "no source: off, never committed";
  struct Source final : modbus::StoreStatusSource {
    modbus::StoreStatusWords w;
    modbus::StoreStatusWords store_status_words() const override { return w; }
  } source;
  source.w = {1, 7, 70000, 3, 0x01020304};
  handler->set_store_status(&source);
  r = body(ask(frame(pdu(0x04, 8990, 8))));
  EXPECT_EQ(r, (Bytes{0x04, 16, 0, 1, 0, 7, 0, 1, 0x11, 0x70, 0, 0, 0, 3, 1, 2, 3, 4})) << "FAULT, 7 s, UDINTs high word first";
  config.word_order = WordOrder::LowFirst;
  r = body(ask(frame(pdu(0x04, 8992, 2))));
  EXPECT_EQ(r, (Bytes{0x04, 4, 0x11, 0x70, 0, 1})) << "low word first";
  EXPECT_EQ(body(ask(frame(pdu(0x04, 8993, 1)))), exception_of(0x04, 0x02)) << "a UDINT cannot be cut";
  EXPECT_EQ(body(ask(frame(pdu(0x03, 8990, 1)))), exception_of(0x03, 0x02)) << "input registers only";
}

}  // namespace
}  // namespace syncplc
