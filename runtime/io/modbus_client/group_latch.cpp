#include "runtime/io/modbus_client/group_latch.hpp"

#include <algorithm>
#include <mutex>
#include <set>

#include "runtime/io/modbus_client/group_handover.hpp"

namespace syncplc {

const char* intern_text(const std::string& text) {
  // Load time only; never freed, so a text stays valid in an event however
  // long the event waits to be printed or stored.
  static std::mutex m;
  static std::set<std::string>* pool = new std::set<std::string>;
  std::lock_guard lock(m);
  return pool->insert(text).first->c_str();
}

GroupTexts make_group_texts(const std::string& driver, const RequestGroup& g) {
  GroupTexts t;
  const std::string who = "modbus_client " + driver + "." + g.name + ": ";
  for (std::size_t s = 0; s < kErrorSlots; ++s)
    t.fault[s] = intern_text(who + std::string(client_error_name(client_error_of_slot(s))));
  t.recovered = intern_text(who + "ok again");
  switch (g.reaction) {
    case StaleReaction::Hold: t.reaction = intern_text(who + "stale past stale_after, holding the last values"); break;
    case StaleReaction::Safe: t.reaction = intern_text(who + "stale past stale_after, inputs set to their safe values"); break;
    case StaleReaction::Stop: t.reaction = intern_text(who + "stale past stale_after, stopping the task"); break;
  }
  return t;
}

void GroupLatch::reset(std::int64_t open_ns, std::uint32_t open_cycle) noexcept {
  st_ = GroupStatus{};
  shown_cycle_ = open_cycle;
  seen_ = 0;
  stale_ = false;
  stale_since_ = 0;
  last_ok_ = open_ns;
  reacted_ = false;
}

void GroupLatch::raise(const ScanContext& ctx, EventKind kind, const char* text, double value) noexcept {
  if (ctx.events) ctx.events->push(Event{ctx.now_ns, ctx.task, -1, kind, text, value});
}

const GroupStatus& GroupLatch::latch(const Cell* r, std::int64_t now, const ScanContext& ctx, Cell* values,
                                     std::uint32_t cycle) noexcept {
  st_.fresh = false;
  const std::uint64_t seq = r[GroupHandover::kSeq].get<std::uint64_t>();
  if (seq != seen_ && seq != 0) {
    seen_ = seq;
    const std::uint16_t err = r[GroupHandover::kError].get<std::uint16_t>();
    if (err == 0) {
      const std::uint32_t n = g_->read_values();
      for (std::uint32_t i = 0; i < n; ++i) values[i] = r[GroupHandover::kValues + i];
      st_.fresh = true;
      st_.sent = r[GroupHandover::kSent].get<std::int64_t>();
      last_ok_ = r[GroupHandover::kStamp].get<std::int64_t>();
      shown_cycle_ = r[GroupHandover::kCycle].get<std::uint32_t>();
      st_.epoch = r[GroupHandover::kEpoch].get<std::uint64_t>();
      if (stale_) raise(ctx, EventKind::Info, texts_.recovered, 0);
      stale_ = false;
      reacted_ = false;
      st_.ok = true;
      st_.error = 0;
    } else {
      if (!stale_) stale_since_ = now;
      if (!stale_ || err != st_.error) raise(ctx, EventKind::DriverFault, texts_.fault[client_error_slot(err)], err);
      stale_ = true;
      st_.ok = false;
      st_.error = err;
      st_.epoch = 0;
    }
  }
  if (stale_ && !reacted_ && now - stale_since_ >= g_->stale_after_ns) {
    reacted_ = true;
    raise(ctx, EventKind::DriverFault, texts_.reaction, static_cast<double>(now - last_ok_) * 1e-6);
    if (g_->reaction == StaleReaction::Stop) ctx.request_stop(texts_.reaction);
  }
  st_.reacting = stale_ && reacted_;
  // A reply published between the latch's clock reading and its acquire is
  // stamped after `now`: its age is 0, not a negative fraction of a µs.
  st_.age_ms = static_cast<double>(std::max<std::int64_t>(now - last_ok_, 0)) * 1e-6;
  // Unsigned difference: right across the 32-bit count's wrap. A request
  // sent after this count was read (free timing) is "this cycle's", 0.
  const std::uint32_t d = cycle - shown_cycle_;
  st_.cycles = d > 0x80000000u ? 0 : d;
  return st_;
}

}  // namespace syncplc
