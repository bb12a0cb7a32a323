#include "runtime/modbus/request_handler.hpp"

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/core/tag_limits.hpp"

#include <modbus/modbus.h>
#include <sys/socket.h>

#include <algorithm>
#include <cmath>

namespace syncplc::modbus {
namespace {

// Function codes served (Modbus Application Protocol V1.1b3 §6).
enum Function : std::uint8_t {
  kReadCoils = 0x01,
  kReadDiscreteInputs = 0x02,
  kReadHoldingRegisters = 0x03,
  kReadInputRegisters = 0x04,
  kWriteSingleCoil = 0x05,
  kWriteSingleRegister = 0x06,
  kWriteMultipleCoils = 0x0F,
  kWriteMultipleRegisters = 0x10,
  kWriteReadRegisters = 0x17,
};

// Quantity limits of the protocol (the same as libmodbus's MODBUS_MAX_*).
constexpr std::uint32_t kMaxReadBits = 2000, kMaxReadRegisters = 125, kMaxWriteBits = 1968,
                        kMaxWriteRegisters = 123, kMaxWriteReadWrite = 121, kMaxWriteReadRead = 125;

// Where the PDU's fields sit in a frame (after the 7-byte MBAP header).
constexpr std::size_t kFunction = 7, kAddress = 8, kQuantity = 10, kByteCount = 12, kData = 13;
// FC 23: read address, read quantity, write address, write quantity, byte count, values.
constexpr std::size_t kWrAddressW = 12, kWrQuantityW = 14, kWrByteCount = 16, kWrData = 17;

// The value a register pair/quad holds, if it is one of type t: 8-bit types
// must fit their range, reals must be finite (a NaN set-point is never what
// an operator meant), BOOL is 0 or 1.
bool registers_to_cell(IecType t, const std::uint16_t* regs, WordOrder order, Cell& out) {
  if (register_width(t) == 1) {
    const std::uint16_t r = regs[0];
    switch (t) {
      case IecType::BOOL: if (r > 1) return false; break;
      case IecType::SINT: { const auto v = static_cast<std::int16_t>(r); if (v < -128 || v > 127) return false; break; }
      case IecType::USINT: case IecType::BYTE: if (r > 255) return false; break;
      default: break;
    }
  }
  out = decode_registers(t, regs, order);
  if (t == IecType::REAL && !std::isfinite(out.get<float>())) return false;
  if (t == IecType::LREAL && !std::isfinite(out.get<double>())) return false;
  return true;
}

bool all_writable(const std::vector<const ModbusPoint*>& points) {
  return std::all_of(points.begin(), points.end(), [](const ModbusPoint* p) { return p->writable; });
}

}  // namespace

std::int64_t deferral_limit_ns(const Program& p, const std::vector<PendingReply::Wait>& waits) {
  std::int64_t period = 0;
  for (const auto& w : waits) period = std::max(period, p.tasks[w.task]->config().period_ns);
  return 2'000'000'000 + 3 * period;  // two scans normally; a stopped task gets 04 after this
}

RequestHandler::RequestHandler(const ModbusConfig& config, Counters& counters) : config_(config), counters_(counters) {
  // The context only frames and sends replies: its address is never connected to.
  ctx_ = modbus_new_tcp("127.0.0.1", 0);
  // Covers every address of every table, so modbus_reply can never index out of it.
  scratch_ = modbus_mapping_new(65536, 65536, 65536, 65536);
  if (!ctx_ || !scratch_) throw std::runtime_error("modbus: cannot allocate the reply context");
  reads_.reserve(kMaxReadBits);
  writes_.reserve(kMaxWriteBits);
  staged_.reserve(kMaxWriteBits);
  staged_task_.reserve(kMaxWriteBits);
  batch_.reserve(kMaxWriteBits);
  batches_.reserve(16);
}

RequestHandler::~RequestHandler() {
  if (scratch_) modbus_mapping_free(scratch_);
  if (ctx_) {
    modbus_set_socket(ctx_, -1);  // the sockets belong to the server
    modbus_free(ctx_);
  }
}

void RequestHandler::set_program(Program& program, const ModbusPlaces& places) {
  program_ = &program;
  map_ = ModbusMap::build(program, ModbusSettings{config_, places});
}

RequestHandler::Outcome RequestHandler::exception(int fd, const std::uint8_t* frame, std::uint8_t code) {
  counters_.count_exception(code);
  // Built here rather than by modbus_reply_exception, which adds 0x80 to the
  // function code in an 8-bit field: a request with function code 0x83 would
  // be answered as if it were a normal read (0x03) response.
  const std::uint8_t reply[kMbapLength + 2] = {frame[0], frame[1], 0, 0, 0, 3, frame[6],
                                               static_cast<std::uint8_t>(frame[kFunction] | 0x80), code};
  return send(fd, reply, sizeof reply, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof reply) ? Outcome::Sent
                                                                                           : Outcome::SendFailed;
}

RequestHandler::Outcome RequestHandler::reply(int fd, const std::uint8_t* frame, std::size_t length) {
  modbus_set_socket(ctx_, fd);
  return modbus_reply(ctx_, frame, static_cast<int>(length), scratch_) > 0 ? Outcome::Sent : Outcome::SendFailed;
}

void RequestHandler::load(ModbusTable t, const std::vector<const ModbusPoint*>& points) {
  owners_.clear();
  bool task_status = false, store_status = false;
  std::uint16_t last = 0xFFFF;
  for (const auto* pt : points) {
    if (pt->status != ModbusPoint::Status::None) {
      (is_store_status(pt->status) ? store_status : task_status) = true;
      continue;
    }
    if (pt->owner == last) continue;  // neighbours usually share an owner
    last = pt->owner;
    if (std::find(owners_.begin(), owners_.end(), last) == owners_.end()) owners_.push_back(last);
  }
  std::uint8_t* bits = t == ModbusTable::Coils ? scratch_->tab_bits : scratch_->tab_input_bits;
  std::uint16_t* regs = t == ModbusTable::HoldingRegisters ? scratch_->tab_registers : scratch_->tab_input_registers;
  const bool bit_table = t == ModbusTable::Coils || t == ModbusTable::DiscreteInputs;
  for (const std::uint16_t owner : owners_) {
    program_->tasks[owner]->with_published([&](const Cell* image) {
      for (const auto* pt : points) {
        if (pt->owner != owner || pt->status != ModbusPoint::Status::None) continue;
        const Cell c = image[pt->cell];
        if (bit_table) bits[pt->address] = (c.raw & 0xFF) ? 1 : 0;
        else if (pt->width == 1 && pt->type != IecType::SINT) regs[pt->address] = static_cast<std::uint16_t>(c.raw);
        else encode_registers(pt->type, c, config_.word_order, regs + pt->address);  // wide values, SINT's sign
      }
    });
  }
  if (task_status) load_task_status(points, regs);
  if (store_status) load_store_status(points, regs);
}

void RequestHandler::load_store_status(const std::vector<const ModbusPoint*>& points, std::uint16_t* regs) {
  const StoreStatusWords w = store_status_ ? store_status_->store_status_words() : StoreStatusWords{};
  for (const auto* pt : points) {
    Cell c;
    switch (pt->status) {
      case ModbusPoint::Status::StoreState: c.set<std::uint16_t>(w.state); break;
      case ModbusPoint::Status::StoreSinceOk: c.set<std::uint16_t>(w.since_ok_s); break;
      case ModbusPoint::Status::StorePending: c.set<std::uint32_t>(w.pending); break;
      case ModbusPoint::Status::StoreDropped: c.set<std::uint32_t>(w.dropped); break;
      case ModbusPoint::Status::StoreFailures: c.set<std::uint32_t>(w.failures); break;
      default: continue;
    }
    if (pt->width == 1) regs[pt->address] = static_cast<std::uint16_t>(c.raw);
    else encode_registers(pt->type, c, config_.word_order, regs + pt->address);
  }
}

void RequestHandler::load_task_status(const std::vector<const ModbusPoint*>& points, std::uint16_t* regs) {
  const std::int64_t epoch = program_->epoch_ns.load(std::memory_order_acquire);
  const std::int64_t now = epoch < 0 ? -1 : monotonic_ns() - epoch;  // on the tasks' time axis
  for (const auto* pt : points) {
    if (pt->status == ModbusPoint::Status::None || is_store_status(pt->status)) continue;
    Task& task = *program_->tasks[pt->owner];
    const SnapshotStamp s = task.published_stamp();
    const std::int64_t period = task.config().period_ns;
    // Age of the newest values: since the release of the scan that made them.
    const std::int64_t age = s.scan == 0 || now < 0 ? 0 : std::max<std::int64_t>(0, now - s.release_ns);
    Cell c;
    switch (pt->status) {
      case ModbusPoint::Status::State: {
        TaskState st = TaskState::Running;
        if (task.stopped()) st = TaskState::Stopped;
        else if (s.scan == 0) st = TaskState::NotStarted;
        else if (now >= 0 && age > 3 * period + 1'000'000'000) st = TaskState::Late;
        c.set<std::uint16_t>(static_cast<std::uint16_t>(st));
        break;
      }
      case ModbusPoint::Status::AgeMs: c.set<std::uint16_t>(static_cast<std::uint16_t>(std::min<std::int64_t>(age / 1'000'000, 65535))); break;
      case ModbusPoint::Status::Scans: c.set<std::uint64_t>(s.scan); break;
      case ModbusPoint::Status::PeriodUs: c.set<std::uint32_t>(static_cast<std::uint32_t>(std::min<std::int64_t>(period / 1000, 0xFFFFFFFF))); break;
      default: break;
    }
    if (pt->width == 1) regs[pt->address] = static_cast<std::uint16_t>(c.raw);
    else encode_registers(pt->type, c, config_.word_order, regs + pt->address);
  }
}

bool RequestHandler::stage_bits(const std::vector<const ModbusPoint*>& points, const std::uint8_t* bits) {
  const std::uint32_t first = points.front()->address;
  for (const auto* pt : points) {
    const std::uint32_t i = pt->address - first;
    Cell c;
    c.set<bool>(((bits[i / 8] >> (i % 8)) & 1) != 0);
    staged_.push_back(QueuedWrite{pt->cell, c});
    staged_task_.push_back(pt->owner);
  }
  return true;
}

bool RequestHandler::stage_registers(const std::vector<const ModbusPoint*>& points, const std::uint8_t* words) {
  const std::uint32_t first = points.front()->address;
  std::uint16_t regs[4];
  for (const auto* pt : points) {
    const std::uint8_t* w = words + 2 * (pt->address - first);
    for (std::uint32_t k = 0; k < pt->width; ++k) regs[k] = get_u16(w + 2 * k);
    Cell c;
    if (!registers_to_cell(pt->type, regs, config_.word_order, c)) return false;
    // A tag's engineering limits hold for every writer from outside (HTTP, HMI, Modbus).
    if (!within_limits(program_->tags[pt->tag], c)) return false;
    staged_.push_back(QueuedWrite{pt->cell, c});
    staged_task_.push_back(pt->owner);
  }
  return true;
}

std::uint8_t RequestHandler::queue_staged(PendingReply* pending) {
  owners_.clear();
  for (const std::uint16_t o : staged_task_)
    if (std::find(owners_.begin(), owners_.end(), o) == owners_.end()) owners_.push_back(o);
  // A stopped task never applies its queue: acknowledging the write would be a lie.
  for (const std::uint16_t owner : owners_)
    if (program_->tasks[owner]->stopped()) return kServerDeviceFailure;
  std::sort(owners_.begin(), owners_.end());  // Task::enqueue_all takes the tasks' locks in index order
  batch_.clear();
  batches_.clear();
  for (const std::uint16_t owner : owners_) {
    const std::size_t first = batch_.size();
    for (std::size_t i = 0; i < staged_.size(); ++i)
      if (staged_task_[i] == owner) batch_.push_back(staged_[i]);
    batches_.push_back(Task::WriteBatch{program_->tasks[owner].get(), nullptr, batch_.size() - first});
  }
  const QueuedWrite* at = batch_.data();
  for (auto& b : batches_) {
    b.writes = at;
    at += b.n;
  }
  // All or nothing: a request whose write spans two tasks is never half applied.
  if (!Task::enqueue_all(batches_.data(), batches_.size())) return kServerDeviceBusy;
  counters_.values_written.fetch_add(batch_.size(), std::memory_order_relaxed);
  // staged_[i] is the value of writes_[i] (stage_bits, stage_registers).
  if (audit_) audit_->written(*program_, client_, writes_.data(), staged_.data(), staged_.size());
  // Read after queuing: publication n + 2 comes from a scan that started after this write was queued.
  if (pending)
    for (const std::uint16_t owner : owners_)
      pending->waits.push_back(PendingReply::Wait{owner, program_->tasks[owner]->published_count() + 2});
  return 0;
}

bool RequestHandler::waits_on_stopped(const PendingReply& pending) const {
  return std::any_of(pending.waits.begin(), pending.waits.end(),
                     [this](const PendingReply::Wait& w) { return program_->tasks[w.task]->stopped(); });
}

RequestHandler::Outcome RequestHandler::handle(int fd, const std::uint8_t* frame, std::size_t length,
                                               PendingReply& pending, std::int64_t now_ns) {
  counters_.requests.fetch_add(1, std::memory_order_relaxed);
  const std::uint8_t unit = frame[kMbapLength - 1];
  if (unit != config_.unit_id && unit != 0 && unit != 255) return exception(fd, frame, kGatewayTargetFailed);
  if (!program_) return exception(fd, frame, kServerDeviceFailure);
  const std::uint8_t fc = frame[kFunction];
  const std::size_t pdu = length - kMbapLength;  // function code and data
  auto u16 = [frame](std::size_t at) { return get_u16(frame + at); };
  staged_.clear();
  staged_task_.clear();

  switch (fc) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters: {
      const bool bits = fc == kReadCoils || fc == kReadDiscreteInputs;
      if (pdu != 5) return exception(fd, frame, kIllegalDataValue);
      const std::uint32_t quantity = u16(kQuantity);
      if (quantity < 1 || quantity > (bits ? kMaxReadBits : kMaxReadRegisters))
        return exception(fd, frame, kIllegalDataValue);
      const ModbusTable t = fc == kReadCoils ? ModbusTable::Coils
                            : fc == kReadDiscreteInputs ? ModbusTable::DiscreteInputs
                            : fc == kReadHoldingRegisters ? ModbusTable::HoldingRegisters
                                                          : ModbusTable::InputRegisters;
      if (!map_.range(t, u16(kAddress), quantity, reads_)) return exception(fd, frame, kIllegalDataAddress);
      load(t, reads_);
      return reply(fd, frame, length);
    }

    case kWriteSingleCoil:
    case kWriteSingleRegister: {
      if (pdu != 5) return exception(fd, frame, kIllegalDataValue);
      const std::uint16_t value = u16(kQuantity);
      if (fc == kWriteSingleCoil && value != 0xFF00 && value != 0x0000) return exception(fd, frame, kIllegalDataValue);
      const ModbusTable t = fc == kWriteSingleCoil ? ModbusTable::Coils : ModbusTable::HoldingRegisters;
      if (config_.read_only || !map_.range(t, u16(kAddress), 1, writes_) || !writes_.front()->writable)
        return exception(fd, frame, kIllegalDataAddress);
      const std::uint8_t data[2] = {frame[kQuantity], frame[kQuantity + 1]};
      if (fc == kWriteSingleCoil) {
        const std::uint8_t bit = value ? 1 : 0;
        stage_bits(writes_, &bit);
      } else if (!stage_registers(writes_, data)) {
        return exception(fd, frame, kIllegalDataValue);
      }
      if (const std::uint8_t code = queue_staged(nullptr)) return exception(fd, frame, code);
      return reply(fd, frame, length);
    }

    case kWriteMultipleCoils:
    case kWriteMultipleRegisters: {
      const bool bits = fc == kWriteMultipleCoils;
      if (pdu < 6) return exception(fd, frame, kIllegalDataValue);
      const std::uint32_t quantity = u16(kQuantity);
      const std::uint32_t bytes = frame[kByteCount];
      if (quantity < 1 || quantity > (bits ? kMaxWriteBits : kMaxWriteRegisters) ||
          bytes != (bits ? (quantity + 7) / 8 : 2 * quantity) || pdu != 6 + bytes)
        return exception(fd, frame, kIllegalDataValue);
      const ModbusTable t = bits ? ModbusTable::Coils : ModbusTable::HoldingRegisters;
      if (config_.read_only || !map_.range(t, u16(kAddress), quantity, writes_) || !all_writable(writes_))
        return exception(fd, frame, kIllegalDataAddress);
      if (bits) stage_bits(writes_, frame + kData);
      else if (!stage_registers(writes_, frame + kData)) return exception(fd, frame, kIllegalDataValue);
      if (const std::uint8_t code = queue_staged(nullptr)) return exception(fd, frame, code);
      return reply(fd, frame, length);
    }

    case kWriteReadRegisters: {
      if (pdu < 10) return exception(fd, frame, kIllegalDataValue);
      const std::uint32_t read_quantity = u16(kQuantity), write_quantity = u16(kWrQuantityW);
      const std::uint32_t bytes = frame[kWrByteCount];
      if (read_quantity < 1 || read_quantity > kMaxWriteReadRead || write_quantity < 1 ||
          write_quantity > kMaxWriteReadWrite || bytes != 2 * write_quantity || pdu != 10 + bytes)
        return exception(fd, frame, kIllegalDataValue);
      if (config_.read_only || !map_.range(ModbusTable::HoldingRegisters, u16(kWrAddressW), write_quantity, writes_) ||
          !map_.range(ModbusTable::HoldingRegisters, u16(kAddress), read_quantity, reads_) || !all_writable(writes_))
        return exception(fd, frame, kIllegalDataAddress);
      if (!stage_registers(writes_, frame + kWrData)) return exception(fd, frame, kIllegalDataValue);
      pending.waits.clear();
      if (const std::uint8_t code = queue_staged(&pending)) return exception(fd, frame, code);
      pending.active = true;
      std::copy(frame, frame + length, pending.frame);
      pending.length = length;
      pending.deadline_ns = now_ns + deferral_limit_ns(*program_, pending.waits);
      return Outcome::Deferred;
    }

    default:
      return exception(fd, frame, kIllegalFunction);
  }
}

bool RequestHandler::ready(const PendingReply& pending, std::int64_t now_ns) const {
  if (now_ns >= pending.deadline_ns) return true;
  if (waits_on_stopped(pending)) return true;  // answered (04, unless it was published) without waiting out the deadline
  return std::all_of(pending.waits.begin(), pending.waits.end(), [this](const PendingReply::Wait& w) {
    return program_->tasks[w.task]->published_count() >= w.published;
  });
}

RequestHandler::Outcome RequestHandler::finish(int fd, PendingReply& pending, std::int64_t now_ns) {
  pending.active = false;
  const bool published = std::all_of(pending.waits.begin(), pending.waits.end(), [this](const PendingReply::Wait& w) {
    return program_->tasks[w.task]->published_count() >= w.published;
  });
  if (!published && (now_ns >= pending.deadline_ns || waits_on_stopped(pending)))
    return exception(fd, pending.frame, kServerDeviceFailure);
  return answer_now(fd, pending);
}

RequestHandler::Outcome RequestHandler::answer_now(int fd, PendingReply& pending) {
  pending.active = false;
  // Checked when it was queued; after an online change the new program may not map it.
  if (!map_.range(ModbusTable::HoldingRegisters, get_u16(pending.frame + kAddress), get_u16(pending.frame + kQuantity),
                  reads_))
    return exception(fd, pending.frame, kServerDeviceFailure);
  load(ModbusTable::HoldingRegisters, reads_);
  // Built here, not by modbus_reply: that would copy the request's values into
  // the read range first, and so show what the client sent where the program
  // has since changed it. This reads back the snapshot that holds the write
  // and what the scan made of it.
  const std::uint16_t first = get_u16(pending.frame + kAddress), count = get_u16(pending.frame + kQuantity);
  std::uint8_t out[kMbapLength + 2 + 2 * kMaxWriteReadRead];
  const std::size_t length = kMbapLength + 2 + 2 * std::size_t{count};
  std::copy(pending.frame, pending.frame + kMbapLength, out);  // transaction id, protocol id, unit id
  out[4] = static_cast<std::uint8_t>((length - 6) >> 8);
  out[5] = static_cast<std::uint8_t>(length - 6);
  out[kFunction] = kWriteReadRegisters;
  out[kFunction + 1] = static_cast<std::uint8_t>(2 * count);
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint16_t r = scratch_->tab_registers[first + i];
    out[kFunction + 2 + 2 * i] = static_cast<std::uint8_t>(r >> 8);
    out[kFunction + 3 + 2 * i] = static_cast<std::uint8_t>(r);
  }
  return send(fd, out, length, MSG_NOSIGNAL) == static_cast<ssize_t>(length) ? Outcome::Sent : Outcome::SendFailed;
}

}  // namespace syncplc::modbus
