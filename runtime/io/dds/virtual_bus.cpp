#include "runtime/io/dds/virtual_bus.hpp"

#include <algorithm>

namespace syncplc {
namespace virtual_bus_impl {

std::string values_text(std::uint32_t n) { return std::to_string(n) + (n == 1 ? " value" : " values"); }

}  // namespace virtual_bus_impl

std::size_t VirtualBus::topic_index(const std::string& name, std::uint32_t values) {
  for (std::size_t i = 0; i < topics_.size(); ++i)
    if (topics_[i].name == name) return i;
  Topic t;
  t.name = name;
  t.count = values;
  topics_.push_back(std::move(t));
  return topics_.size() - 1;
}

void VirtualBus::relayout(Topic& t, std::uint32_t values) {
  t.count = values;
  t.slots.clear();
  t.values.clear();
  t.capacity = 0;
}

void VirtualBus::size_ring(Topic& t) {
  if (t.period_ns <= 0) return;  // no publisher yet: sized when it comes
  std::uint64_t need = 4;
  for (const auto& s : subs_) {
    if (!s.open || &topics_[s.topic] != &t) continue;
    const std::int64_t span = s.delay_ns + std::max(s.period_ns, t.period_ns) + t.period_ns;
    need = std::max<std::uint64_t>(need, static_cast<std::uint64_t>((span + t.period_ns - 1) / t.period_ns) + 2);
  }
  if (need <= t.capacity) return;
  // Keep what is in the ring at its sequence's new place.
  std::vector<Slot> slots(need);
  std::vector<double> values(need * t.count);
  for (std::uint64_t q = t.head > t.capacity ? t.head - t.capacity + 1 : 1; t.capacity && q <= t.head; ++q) {
    slots[q % need] = t.slots[q % t.capacity];
    std::copy_n(&t.values[(q % t.capacity) * t.count], t.count, &values[(q % need) * t.count]);
  }
  t.slots = std::move(slots);
  t.values = std::move(values);
  t.capacity = need;
}

int VirtualBus::advertise(const std::string& topic, std::uint32_t values, const std::string& node, std::int64_t period_ns,
                          std::string* error) {
  using virtual_bus_impl::values_text;
  const std::size_t ti = topic_index(topic, values);
  Topic& t = topics_[ti];
  if (!t.publisher.empty() && t.publisher != node) {
    *error = "dds: topic " + topic + ": node '" + t.publisher + "' publishes it already; node '" + node +
             "' may not publish it too";
    return -1;
  }
  for (const auto& s : subs_)
    if (s.open && s.topic == ti && t.count != values) {
      *error = "dds: topic " + topic + ": node '" + s.node + "' takes " + values_text(t.count) + ", node '" + node +
               "' publishes " + values_text(values) + ": the nodes' projects do not match";
      return -1;
    }
  if (t.count != values) relayout(t, values);  // no subscriber holds the old count: the publisher's is the topic's
  t.publisher = node;
  t.period_ns = period_ns;
  t.writer = ++writers_;
  size_ring(t);
  pubs_.push_back(Publisher{ti, t.writer});
  return static_cast<int>(pubs_.size() - 1);
}

int VirtualBus::subscribe(const std::string& topic, std::uint32_t values, const std::string& node, std::int64_t delay_ns,
                          std::int64_t period_ns, std::string* error) {
  using virtual_bus_impl::values_text;
  const std::size_t ti = topic_index(topic, values);
  Topic& t = topics_[ti];
  if (t.count != values) {
    // Who holds the topic's count: its publisher, else a subscriber. A topic
    // nobody holds any more takes the newcomer's count.
    std::string holder = t.publisher.empty() ? std::string() : "' publishes ";
    std::string who = t.publisher;
    for (const auto& s : subs_)
      if (holder.empty() && s.open && s.topic == ti) holder = "' takes ", who = s.node;
    if (!holder.empty()) {
      *error = "dds: topic " + topic + ": node '" + who + holder + values_text(t.count) + ", node '" + node +
               "' takes " + values_text(values) + ": the nodes' projects do not match";
      return -1;
    }
    relayout(t, values);
  }
  Subscriber s;
  s.topic = ti;
  s.node = node;
  s.delay_ns = delay_ns;
  s.period_ns = period_ns;
  s.next = t.head + 1;  // a subscriber sees samples published from now on
  s.open = true;
  subs_.push_back(s);
  size_ring(t);
  return static_cast<int>(subs_.size() - 1);
}

void VirtualBus::withdraw_publisher(int id) noexcept {
  if (id < 0 || static_cast<std::size_t>(id) >= pubs_.size()) return;
  const Publisher& p = pubs_[static_cast<std::size_t>(id)];
  Topic& t = topics_[p.topic];
  if (t.writer == p.writer) t.publisher.clear();
}

void VirtualBus::withdraw_subscriber(int id) noexcept {
  if (id < 0 || static_cast<std::size_t>(id) >= subs_.size()) return;
  subs_[static_cast<std::size_t>(id)].open = false;
}

void VirtualBus::publish(int id, std::uint64_t scan, std::int64_t release_ns, const Cell* values) noexcept {
  const Publisher& p = pubs_[static_cast<std::size_t>(id)];
  Topic& t = topics_[p.topic];
  if (t.capacity == 0 || t.writer != p.writer) return;  // replaced: its samples no longer go out
  ++t.head;
  const std::size_t at = static_cast<std::size_t>(t.head % t.capacity);
  t.slots[at] = Slot{t.writer, scan, release_ns};
  for (std::uint32_t v = 0; v < t.count; ++v) t.values[at * t.count + v] = values[v].get<double>();
}

std::vector<std::string> VirtualBus::unmatched() const {
  std::vector<std::string> out;
  for (const auto& s : subs_) {
    const Topic& t = topics_[s.topic];
    if (s.open && t.publisher.empty())
      out.push_back("dds: node '" + s.node + "' subscribes topic " + t.name + ", which no node of the system publishes");
  }
  return out;
}

}  // namespace syncplc
