#include "runtime/io/dds/subscription_latch.hpp"

#include "runtime/io/modbus_client/group_latch.hpp"  // intern_text

namespace syncplc::dds {

SubscriptionTexts make_subscription_texts(const std::string& driver, const Subscription& s) {
  const std::string who = "dds " + driver + "." + s.topic + ": ";
  SubscriptionTexts t;
  switch (s.reaction) {
    case StaleReaction::Hold: t.stale = intern_text(who + "stale past stale_after, holding the last values"); break;
    case StaleReaction::Safe: t.stale = intern_text(who + "stale past stale_after, values set to their safe values"); break;
    case StaleReaction::Stop: t.stale = intern_text(who + "stale past stale_after, stopping the task"); break;
  }
  t.recovered = intern_text(who + "samples arrive again");
  return t;
}

void SubscriptionLatch::reset() noexcept {
  st_ = SubscriptionStatus{};
  seen_ = 0;
  started_ = false;
  since_ = 0;
  reacted_ = false;
}

const SubscriptionStatus& SubscriptionLatch::latch(const Cell* c, const ScanContext& ctx, Cell* values,
                                                   std::int64_t started) noexcept {
  if (!started_) {
    started_ = true;
    since_ = ctx.scan;
  }
  st_.fresh = false;
  const std::uint64_t received = c[SubscriptionCells::kReceived].get<std::uint64_t>();
  if (received != seen_ && received != 0) {
    seen_ = received;
    st_.fresh = true;
    since_ = ctx.scan;
    st_.scan = c[SubscriptionCells::kScan].get<std::uint64_t>();
    const std::int64_t pub_started = c[SubscriptionCells::kStarted].get<std::int64_t>();
    st_.has_phase = started > 0 && pub_started > 0 && ctx.dt_ns > 0;
    if (st_.has_phase) {
      const std::int64_t t = ctx.dt_ns;
      std::int64_t d = (started - pub_started) % t;  // C++: the sign of the dividend
      if (d > t / 2) d -= t;
      if (d <= -t / 2) d += t;
      st_.phase_ns = d;
    }
    if (values)
      for (std::uint32_t i = 0; i < sub_->values; ++i) values[i] = c[SubscriptionCells::kValues + i];
  }
  st_.lost = static_cast<std::uint32_t>(c[SubscriptionCells::kLost].get<std::uint64_t>());
  st_.late = static_cast<std::uint32_t>(c[SubscriptionCells::kLate].get<std::uint64_t>());
  const std::uint64_t age = ctx.scan - since_;
  st_.age = age > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint32_t>(age);
  const bool stale = age > sub_->stale_after;
  st_.ok = seen_ != 0 && !stale;
  if (stale) {
    st_.reacting = true;
    if (!reacted_) {
      reacted_ = true;
      if (ctx.events) ctx.events->push(Event{ctx.now_ns, ctx.task, -1, EventKind::DriverFault, texts_.stale, static_cast<double>(age)});
    }
    if (sub_->reaction == StaleReaction::Safe && values)
      for (std::uint32_t i = 0; i < sub_->values; ++i) values[i].set<double>(sub_->safe[i]);
    if (sub_->reaction == StaleReaction::Stop) ctx.request_stop(texts_.stale);
  } else {
    if (reacted_ && ctx.events) ctx.events->push(Event{ctx.now_ns, ctx.task, -1, EventKind::Info, texts_.recovered, 0});
    st_.reacting = false;
    reacted_ = false;
  }
  return st_;
}

}  // namespace syncplc::dds
