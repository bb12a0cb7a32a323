// libFuzzer harness on the Modbus request path: the bytes of one TCP
// connection go through the server's framing (check_frame) and request
// handler exactly as the server thread feeds them, against the handler
// tests' project (every table, width and access), while the program scans in
// virtual time.
// Besides ASan/UBSan, it checks that every reply is a well-formed Modbus TCP
// frame answering its request (same transaction and unit, the request's
// function code or its exception), and that a bad header ends the stream.
//
// Input: byte 0 picks the configuration (bit 0 low word first, bit 1 read
// only); the rest is the stream.
#include <fcntl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "runtime/core/virtual_clock.hpp"
#include "runtime/modbus/frame.hpp"
#include "runtime/modbus/request_handler.hpp"
#include "runtime/project/loader.hpp"
#include "tests/modbus/handler_project.hpp"

namespace {

using namespace syncplc;
using namespace syncplc::modbus;


struct World {
  std::unique_ptr<Program> program;
  ModbusPlaces places;
  std::unique_ptr<VirtualClock> clock;
  std::int64_t now = 0;
  int fds[2];
  ModbusConfig configs[4];
  Counters counters;
  std::unique_ptr<RequestHandler> handlers[4];

  World() {
    auto r = load_project_text(testing::kHandlerProject, "handler_project.yaml");
    if (!r.ok()) {
      for (const auto& d : r.diagnostics.list()) std::fprintf(stderr, "%s\n", d.text().c_str());
      std::abort();
    }
    program = std::move(r.program);
    places = r.modbus.places;
    clock = std::make_unique<VirtualClock>(*program);
    if (socketpair(AF_UNIX, SOCK_STREAM, 0, fds) != 0) std::abort();
    fcntl(fds[0], F_SETFL, O_NONBLOCK);  // as the server's sockets
    fcntl(fds[1], F_SETFL, O_NONBLOCK);
    for (int i = 0; i < 4; ++i) {
      configs[i].word_order = (i & 1) ? WordOrder::LowFirst : WordOrder::HighFirst;
      configs[i].read_only = (i & 2) != 0;
      handlers[i] = std::make_unique<RequestHandler>(configs[i], counters);
      handlers[i]->set_program(*program, places);
    }
    advance();
  }
  void advance() {
    now += 1'000'000;
    clock->run_until(now, true);
  }
  // The reply to `request`: whole, well formed, and answering it.
  void check_reply(const std::uint8_t* request) {
    std::uint8_t buf[512];
    const ssize_t n = read(fds[1], buf, sizeof buf);
    if (n < 9) std::abort();                                   // every request gets an answer
    const std::size_t len = static_cast<std::size_t>(n);
    if (buf[0] != request[0] || buf[1] != request[1]) std::abort();  // transaction id
    if (buf[2] != 0 || buf[3] != 0) std::abort();                   // protocol id
    if (get_u16(buf + 4) != len - 6) std::abort();                  // one frame, length field right
    if (buf[6] != request[6]) std::abort();                         // unit id
    if (buf[7] != request[7] && buf[7] != (request[7] | 0x80)) std::abort();
    if ((buf[7] & 0x80) && len != 9) std::abort();
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static World w;
  if (size < 1) return 0;
  RequestHandler& h = *w.handlers[data[0] & 3];
  const std::uint8_t* stream = data + 1;
  std::size_t left = size - 1;
  PendingReply pending;
  while (left > 0) {
    const FrameCheck f = check_frame(stream, left);
    if (f.status != FrameStatus::Complete) break;  // Bad closes the connection; Incomplete waits forever
    if (f.length > kMaxFrameLength || f.length > left) std::abort();
    const auto outcome = h.handle(w.fds[0], stream, f.length, pending, w.now);
    if (outcome == RequestHandler::Outcome::SendFailed) std::abort();  // the peer reads everything
    if (outcome == RequestHandler::Outcome::Deferred) {
      if (h.ready(pending, w.now)) std::abort();  // never before a scan has run
      while (!h.ready(pending, w.now)) w.advance();
      if (h.finish(w.fds[0], pending, w.now) != RequestHandler::Outcome::Sent) std::abort();
    }
    w.check_reply(stream);
    stream += f.length;
    left -= f.length;
  }
  w.advance();  // apply what was queued, so queues do not stay full across inputs
  return 0;
}
