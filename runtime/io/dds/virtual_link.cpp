#include "runtime/io/dds/virtual_link.hpp"

namespace syncplc::dds {

bool VirtualLink::open(std::string* error) {
  close();
  for (const auto& p : s_.publish) {
    const int id = bus_->advertise(p.topic, p.values, s_.node, period_ns_, error);
    if (id < 0) {
      close();
      return false;
    }
    pub_ids_.push_back(id);
  }
  sub_state_.resize(s_.subscribe.size());
  for (std::size_t i = 0; i < s_.subscribe.size(); ++i) {
    const auto& sub = s_.subscribe[i];
    Sub& st = sub_state_[i];
    st = Sub{};
    st.id = bus_->subscribe(sub.topic, sub.values, s_.node, s_.inject.delay_ns, period_ns_, error);
    if (st.id < 0) {
      close();
      return false;
    }
    // Each subscription's loss stream depends on its topic, not on the
    // order of the subscriptions in the file.
    st.rng = SimRandom{seed_ ^ s_.inject.seed * 0x9E3779B97F4A7C15ULL ^ fnv1a64(sub.topic)};
  }
  last_sent_.assign(s_.publish.size(), 0);
  sent_any_.assign(s_.publish.size(), false);
  clear_subscriptions();
  return true;
}

void VirtualLink::close() noexcept {
  for (int id : pub_ids_) bus_->withdraw_publisher(id);
  for (const auto& st : sub_state_)
    if (st.id >= 0) bus_->withdraw_subscriber(st.id);
  pub_ids_.clear();
  sub_state_.clear();
}

void VirtualLink::poll(std::int64_t now_ns) noexcept {
  for (std::size_t i = 0; i < sub_state_.size(); ++i) {
    Sub& st = sub_state_[i];
    const std::uint32_t count_values = s_.subscribe[i].values;
    bus_->take(st.id, now_ns, [&](const VirtualBus::Sample& m) {
      if (s_.inject.loss > 0 && st.rng.chance(s_.inject.loss)) {
        counters_.injected_lost.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      count(st.intake.accept(subs_[i], m.writer, m.scan, 0, m.values, count_values));
    });
  }
}

void VirtualLink::hand_over() noexcept {
  for (std::size_t i = 0; i < pub_ids_.size(); ++i) {
    const Cell* c = pubs_[i].acquire();
    const std::uint64_t scan = c[PublicationCells::kScan].get<std::uint64_t>();
    if (sent_any_[i] && scan == last_sent_[i]) continue;  // nothing new (outputs held)
    sent_any_[i] = true;
    last_sent_[i] = scan;
    bus_->publish(pub_ids_[i], scan, c[PublicationCells::kTime].get<std::int64_t>(), c + PublicationCells::kValues);
    counters_.sent.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace syncplc::dds
