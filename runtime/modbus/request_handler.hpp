// Answers Modbus TCP requests from the tags of a running program
// (docs/modbus.md). Everything a request can get wrong is judged here, in
// the order of the Modbus Application Protocol V1.1b3 (§6, the state
// diagrams of each function): function code (exception 01), then quantity
// and frame length (03), then addresses and access (02), then the values
// (03). Only a request that has passed every check reaches libmodbus's
// modbus_reply, which builds and sends the normal response from a scratch
// mapping the handler fills from the tasks' published snapshots; exception
// responses (9 bytes) and the response to a write and read (FC 23, whose
// read part must come from the snapshot, not from the request) are built
// here. That order also keeps modbus_reply away from its own error paths,
// which sleep for the response timeout and flush the socket (libmodbus
// 3.1.6): the server thread must never sleep.
//
// Reads take each owning task's latest published snapshot once, under that
// task's snapshot lock, so a request never mixes two scans of one task.
// Writes become QueuedWrites, one batch per owning task, all queued or
// none, applied at the start of each task's next scan in arrival order; the
// reply is sent after they are queued. A write that cannot take effect is
// not acknowledged: when any owning task has stopped (Task::stopped: its
// watchdog stopped it, or the supervisor gave up on a scan that did not
// end) the whole request is exception 04 and nothing of it is queued, for
// any task — checked after the address and value checks, before the queues'
// room (06). A write and read (FC 23) whose task stops while it waits gets 04
// at once. A write and read (FC 23) is answered
// once the write is in a published snapshot (Task::published_count), so its
// read part shows it as the program left it.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "runtime/modbus/modbus_config.hpp"
#include "runtime/core/program.hpp"
#include "runtime/modbus/audit.hpp"
#include "runtime/modbus/store_status_source.hpp"
#include "runtime/modbus/counters.hpp"
#include "runtime/modbus/frame.hpp"
#include "runtime/modbus/register_map.hpp"

typedef struct _modbus modbus_t;
struct _modbus_mapping_t;

namespace syncplc::modbus {

// Exception codes (Modbus Application Protocol V1.1b3 §7).
enum Exception : std::uint8_t {
  kIllegalFunction = 0x01,
  kIllegalDataAddress = 0x02,
  kIllegalDataValue = 0x03,
  kServerDeviceFailure = 0x04,
  kServerDeviceBusy = 0x06,
  kGatewayTargetFailed = 0x0B,
};

// A write and read (FC 23) waiting for its write to be published.
struct PendingReply {
  bool active = false;
  std::uint8_t frame[kMaxFrameLength] = {};
  std::size_t length = 0;
  std::int64_t deadline_ns = 0;
  struct Wait {
    std::uint16_t task;
    std::uint64_t published;  // Task::published_count() to reach
  };
  std::vector<Wait> waits;
};

// How long a write and read may wait for its tasks' publications before it
// is answered with exception 04 (a stopped task): two seconds and three periods.
std::int64_t deferral_limit_ns(const Program& p, const std::vector<PendingReply::Wait>& waits);

class RequestHandler {
 public:
  RequestHandler(const ModbusConfig& config, Counters& counters);
  ~RequestHandler();
  RequestHandler(const RequestHandler&) = delete;
  RequestHandler& operator=(const RequestHandler&) = delete;

  // The program whose tags are served, with the tags' explicit places (its
  // map is built here). The program must outlive its use; set another one
  // (after an online change) between requests.
  void set_program(Program& program, const ModbusPlaces& places = {});
  const ModbusMap& map() const { return map_; }
  // Every write queued is told to `audit` with the client of the request
  // being handled (set_client, by the server before handle()).
  void set_audit(ServerAudit* audit) { audit_ = audit; }
  void set_client(ClientAddress client) { client_ = client; }
  // Where the store status block's values come from; null: the block reads as "off".
  void set_store_status(const StoreStatusSource* source) { store_status_ = source; }

  enum class Outcome : std::uint8_t {
    Sent,        // the reply (normal or exception) went out whole
    Deferred,    // FC 23 waits in `pending`: call ready() and finish() later
    SendFailed,  // the socket took less than the whole reply: close the connection
  };
  // One whole frame (check_frame said Complete), answered on socket fd.
  Outcome handle(int fd, const std::uint8_t* frame, std::size_t length, PendingReply& pending, std::int64_t now_ns);
  // A deferred reply can be sent (its write is published, or its deadline passed).
  bool ready(const PendingReply& pending, std::int64_t now_ns) const;
  // Sends it: the read part, or exception 04 when the write was not published by the deadline.
  Outcome finish(int fd, PendingReply& pending, std::int64_t now_ns);
  // Sends it now, its read part from the snapshots of the program set now:
  // after an online change, whose new program starts with the values the old
  // one ended with, its queued writes included. Exception 04 when the new
  // program does not map the read range.
  Outcome answer_now(int fd, PendingReply& pending);

 private:
  Outcome exception(int fd, const std::uint8_t* frame, std::uint8_t code);
  Outcome reply(int fd, const std::uint8_t* frame, std::size_t length);
  // Fills the scratch mapping for [address, address+count) of table t from the snapshots.
  void load(ModbusTable t, const std::vector<const ModbusPoint*>& points);
  // The task status registers among `points` (register_map.hpp, kTaskStatusRegisters).
  void load_task_status(const std::vector<const ModbusPoint*>& points, std::uint16_t* regs);
  // The store status registers among `points` (register_map.hpp, kStoreStatusRegisters).
  void load_store_status(const std::vector<const ModbusPoint*>& points, std::uint16_t* regs);
  // Decodes and checks the values a write carries (bits: one per coil; registers:
  // big-endian words). False when a value is outside its tag's type (exception 03).
  bool stage_bits(const std::vector<const ModbusPoint*>& points, const std::uint8_t* bits);
  bool stage_registers(const std::vector<const ModbusPoint*>& points, const std::uint8_t* words);
  // Queues the staged writes, one batch per owning task, all or none. 0, or
  // the exception: 04 when an owning task has stopped, 06 when a queue was full.
  std::uint8_t queue_staged(PendingReply* waits);
  // A task that pending waits for has stopped: its write will never be published.
  bool waits_on_stopped(const PendingReply& pending) const;

  const ModbusConfig& config_;
  Counters& counters_;
  Program* program_ = nullptr;
  ModbusMap map_;
  ServerAudit* audit_ = nullptr;
  const StoreStatusSource* store_status_ = nullptr;
  ClientAddress client_;
  modbus_t* ctx_ = nullptr;
  _modbus_mapping_t* scratch_ = nullptr;
  std::vector<const ModbusPoint*> reads_, writes_;  // the points of a request (reused: no allocation)
  std::vector<QueuedWrite> staged_;           // cell values, in address order
  std::vector<std::uint16_t> staged_task_;    // owner of each staged value
  std::vector<QueuedWrite> batch_;            // staged_, grouped by owning task
  std::vector<Task::WriteBatch> batches_;     // one per owning task, into batch_
  std::vector<std::uint16_t> owners_;
};

}  // namespace syncplc::modbus
