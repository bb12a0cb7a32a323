#include "runtime/io/dds/dds_link.hpp"

#include <dds/dds.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <latch>
#include <map>
#include <random>
#include <string>
#include <mutex>

#include "runtime/core/monotonic_clock.hpp"
#include "runtime/io/dds/delay_line.hpp"
#include "runtime/io/dds/node_sample.h"
#include "runtime/io/dds/subscription_intake.hpp"

namespace syncplc::dds {
namespace dds_link_impl {

std::string rc_text(dds_return_t rc) { return dds_strretcode(rc); }

// What every writer and reader tells its peers in its user data: the node
// and the topic's layout, so a node can check at start that its peers agree
// (check_peers).
std::string endpoint_tag(const std::string& node, const std::string& topic, std::uint32_t values) {
  return "syncplc1 node=" + node + " values=" + std::to_string(values) + " layout=" +
         std::to_string(layout_word(topic, values));
}

struct PeerTag {
  std::string node;
  std::uint32_t values = 0, layout = 0;
};

// The tag of a matched endpoint; false for a non-syncplc endpoint.
bool peer_tag(const dds_builtintopic_endpoint_t* ep, PeerTag& out) {
  void* data = nullptr;
  size_t size = 0;
  if (!ep || !ep->qos || !dds_qget_userdata(ep->qos, &data, &size) || !data) return false;
  const std::string text(static_cast<const char*>(data), size);
  dds_free(data);
  if (text.rfind("syncplc1 ", 0) != 0) return false;
  auto field = [&](const char* key) -> std::string {
    const std::string k = std::string(" ") + key + "=";
    const auto at = text.find(k);
    if (at == std::string::npos) return {};
    const auto end = text.find(' ', at + k.size());
    return text.substr(at + k.size(), end == std::string::npos ? std::string::npos : end - at - k.size());
  };
  out.node = field("node");
  try {
    out.values = static_cast<std::uint32_t>(std::stoul(field("values")));
    out.layout = static_cast<std::uint32_t>(std::stoul(field("layout")));
  } catch (...) {
    return false;
  }
  return true;
}

// Keep-last QoS of a cyclic control loop (docs/dds.md, "QoS"): only the
// newest sample matters, a late one is worth nothing.
dds_qos_t* loop_qos(const DdsSettings& s, std::int32_t depth, const std::string& tag) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_userdata(q, tag.data(), tag.size());
  if (s.reliability == Reliability::Reliable) dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(1));
  else dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  if (s.deadline_ns > 0) dds_qset_deadline(q, s.deadline_ns);
  if (s.liveliness_ns > 0) dds_qset_liveliness(q, DDS_LIVELINESS_AUTOMATIC, s.liveliness_ns);
  return q;
}

// The DDS domains this process has made, shared by its dds drivers: a
// domain is made with the first driver's network settings and deleted with
// the last driver that uses it (deleting a domain deletes every participant
// in it). open() and close() only, never the scan.
class Domains {
 public:
  static Domains& instance() {
    static Domains* d = new Domains;  // lives as long as the process; drivers close before exit
    return *d;
  }
  // The domain's handle (> 0), or a DDS return code (< 0).
  dds_entity_t acquire(std::uint32_t id, const std::string& config) {
    std::lock_guard lock(m_);
    auto it = domains_.find(id);
    if (it != domains_.end()) {
      ++it->second.users;
      return it->second.handle;
    }
    const dds_entity_t h = dds_create_domain(id, config.c_str());
    if (h < 0) return h;
    domains_[id] = {h, 1};
    return h;
  }
  void release(std::uint32_t id) {
    std::lock_guard lock(m_);
    auto it = domains_.find(id);
    if (it == domains_.end()) return;
    if (--it->second.users == 0) {
      dds_delete(it->second.handle);
      domains_.erase(it);
    }
  }

 private:
  struct Entry {
    dds_entity_t handle = 0;
    int users = 0;
  };
  std::mutex m_;
  std::map<std::uint32_t, Entry> domains_;
};

// The driver's threads: named, and SCHED_FIFO at `priority` where the
// process may (else they stay at normal scheduling: no error, the summary of
// `syncplc check` says what was asked).
void thread_setup(const char* name, int priority) {
  pthread_setname_np(pthread_self(), name);
  if (priority <= 0) return;
  sched_param p{};
  p.sched_priority = priority;
  pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
}

}  // namespace dds_link_impl

DdsLink::~DdsLink() { close(); }

std::string DdsLink::cyclone_config(const DdsSettings& s) {
  // Settings were checked at load (no XML metacharacters in addresses or names).
  std::string x = "<CycloneDDS><Domain id=\"any\"><General>";
  if (!s.interface.empty()) {
    const bool address = s.interface.find_first_of(".:") != std::string::npos;
    x += "<Interfaces><NetworkInterface " + std::string(address ? "address" : "name") + "=\"" + s.interface +
         "\"/></Interfaces>";
  }
  // Explicit peers: unicast discovery, no multicast (a fixed cell; what works
  // across network namespaces and on networks that drop multicast).
  if (!s.peers.empty()) x += "<AllowMulticast>false</AllowMulticast>";
  x += "</General><Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>63</MaxAutoParticipantIndex>";
  if (!s.peers.empty()) {
    x += "<Peers>";
    for (const auto& p : s.peers) x += "<Peer address=\"" + p + "\"/>";
    x += "</Peers>";
  }
  x += "</Discovery>";
  if (s.shared_memory) x += "<SharedMemory><Enable>true</Enable></SharedMemory>";
  x += "</Domain></CycloneDDS>";
  return x;
}

bool DdsLink::open(std::string* error) {
  using namespace dds_link_impl;
  close();
  const std::string config = cyclone_config(s_);
  // Another driver of this process may have made the domain already: it is
  // shared (the first driver's network settings hold for it).
  const dds_entity_t domain = Domains::instance().acquire(s_.domain, config);
  if (domain < 0) {
    *error = "dds: cannot create DDS domain " + std::to_string(s_.domain) + " with these network settings: " + rc_text(domain);
    return false;
  }
  domain_held_ = true;
  participant_ = dds_create_participant(s_.domain, nullptr, nullptr);
  if (participant_ < 0) {
    *error = "dds: cannot join DDS domain " + std::to_string(s_.domain) + ": " + rc_text(participant_);
    participant_ = 0;
    close();
    return false;
  }
  auto fail = [&](const std::string& what, dds_return_t rc) {
    *error = "dds: " + what + ": " + rc_text(rc);
    close();
    return false;
  };
  // A writer (history depth 1) or a reader (depth 8) of a topic, with its tag.
  auto endpoint = [&](const std::string& name, std::uint32_t values, bool writer) -> dds_entity_t {
    const dds_entity_t topic = dds_create_topic(participant_, &syncplc_NodeSample_desc, wire_topic(name).c_str(), nullptr, nullptr);
    if (topic < 0) {
      fail("topic " + name, topic);
      return topic;
    }
    dds_qos_t* q = loop_qos(s_, writer ? 1 : 8, endpoint_tag(s_.node, name, values));
    const dds_entity_t e = writer ? dds_create_writer(participant_, topic, q, nullptr) : dds_create_reader(participant_, topic, q, nullptr);
    dds_delete_qos(q);
    if (e < 0) fail((writer ? "writer of " : "reader of ") + name, e);
    return e;
  };
  for (const auto& p : s_.publish) {
    const dds_entity_t w = endpoint(p.topic, p.values, true);
    if (w < 0) return false;
    writers_.push_back(w);
  }
  waitset_ = dds_create_waitset(participant_);
  guard_ = dds_create_guardcondition(participant_);
  if (waitset_ < 0 || guard_ < 0) return fail("waitset", waitset_ < 0 ? waitset_ : guard_);
  dds_waitset_attach(waitset_, guard_, -1);
  for (std::size_t i = 0; i < s_.subscribe.size(); ++i) {
    const auto& sub = s_.subscribe[i];
    const dds_entity_t r = endpoint(sub.topic, sub.values, false);
    if (r < 0) return false;
    readers_.push_back(r);
    const dds_entity_t cond = dds_create_readcondition(r, DDS_ANY_STATE);
    if (cond < 0) return fail("read condition of " + sub.topic, cond);
    conditions_.push_back(cond);
    dds_waitset_attach(waitset_, cond, static_cast<dds_attach_t>(i));
  }
  if (!check_peers(error)) {
    close();
    return false;
  }
  clear_subscriptions();
  stop_ = false;
  // open() returns when both threads have made their buffers: what they
  // allocate, they allocate before the first scan.
  std::latch ready(2);
  send_ = std::thread([this, &ready] { send_loop(ready); });
  receive_ = std::thread([this, &ready] { receive_loop(ready); });
  ready.wait();
  return true;
}

bool DdsLink::check_peers(std::string* error) {
  using namespace dds_link_impl;
  if (s_.startup_check_ns <= 0) return true;
  const std::int64_t until = monotonic_ns() + s_.startup_check_ns;
  constexpr std::size_t kMax = 64;
  dds_instance_handle_t handles[kMax];
  for (;;) {
    bool all_met = true;
    // One entity's matched endpoints: false (with *error) on a layout that is not ours.
    auto check = [&](dds_entity_t e, bool writer, const std::string& topic, std::uint32_t values) {
      const dds_return_t n = writer ? dds_get_matched_subscriptions(e, handles, kMax) : dds_get_matched_publications(e, handles, kMax);
      if (n <= 0) {
        all_met = false;
        return true;
      }
      for (dds_return_t i = 0; i < n && i < static_cast<dds_return_t>(kMax); ++i) {
        dds_builtintopic_endpoint_t* ep = writer ? dds_get_matched_subscription_data(e, handles[i])
                                                 : dds_get_matched_publication_data(e, handles[i]);
        PeerTag tag;
        const bool ours = peer_tag(ep, tag);
        if (ep) dds_builtintopic_free_endpoint(ep);
        if (ours && tag.layout != layout_word(topic, values)) {
          *error = "dds: topic " + topic + ": node '" + tag.node + "' " + (writer ? "takes " : "publishes ") +
                   std::to_string(tag.values) + (tag.values == 1 ? " value" : " values") + ", this node " +
                   (writer ? "publishes " : "takes ") + std::to_string(values) +
                   ": the nodes' projects do not match; this node is not started";
          return false;
        }
      }
      return true;
    };
    for (std::size_t i = 0; i < writers_.size(); ++i)
      if (!check(writers_[i], true, s_.publish[i].topic, s_.publish[i].values)) return false;
    for (std::size_t i = 0; i < readers_.size(); ++i)
      if (!check(readers_[i], false, s_.subscribe[i].topic, s_.subscribe[i].values)) return false;
    if (all_met || monotonic_ns() >= until) return true;
    dds_sleepfor(DDS_MSECS(10));
  }
}

void DdsLink::close() noexcept {
  stop_ = true;
  signal_.hand_over();
  if (guard_ > 0) dds_set_guardcondition(guard_, true);
  if (send_.joinable()) send_.join();
  if (receive_.joinable()) receive_.join();
  if (participant_ > 0) dds_delete(participant_);  // and every entity it owns
  participant_ = waitset_ = guard_ = 0;
  if (domain_held_) dds_link_impl::Domains::instance().release(s_.domain);
  domain_held_ = false;
  writers_.clear();
  readers_.clear();
  conditions_.clear();
}

void DdsLink::send_loop(std::latch& ready) noexcept {
  dds_link_impl::thread_setup("dds-send", s_.thread_priority);
  syncplc_NodeSample sample{};
  std::vector<std::uint64_t> last(s_.publish.size(), 0);
  std::vector<bool> any(s_.publish.size(), false);
  std::vector<std::uint32_t> layout(s_.publish.size());
  for (std::size_t i = 0; i < layout.size(); ++i) layout[i] = layout_word(s_.publish[i].topic, s_.publish[i].values);
  std::uint32_t seen = signal_.count();
  ready.count_down();
  while (!stop_.load(std::memory_order_acquire)) {
    const std::uint32_t now = signal_.wait(seen, monotonic_ns() + 100'000'000, stop_);
    if (now == seen) continue;  // timed out (no scan handed over) or stopping
    seen = now;
    for (std::size_t i = 0; i < s_.publish.size(); ++i) {
      const Cell* c = pubs_[i].acquire();
      const std::uint64_t scan = c[PublicationCells::kScan].get<std::uint64_t>();
      if (any[i] && scan == last[i]) continue;  // nothing new (outputs held)
      any[i] = true;
      last[i] = scan;
      const auto& p = s_.publish[i];
      sample.layout = layout[i];
      sample.scan = scan;
      sample.time_ns = c[PublicationCells::kTime].get<std::int64_t>();
      sample.started_ns = c[PublicationCells::kStarted].get<std::int64_t>();
      sample.count = p.values;
      for (std::uint32_t v = 0; v < p.values; ++v) sample.values[v] = c[PublicationCells::kValues + v].get<double>();
      if (dds_write(writers_[i], &sample) < 0) counters_.write_errors.fetch_add(1, std::memory_order_relaxed);
      else counters_.sent.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

void DdsLink::receive_loop(std::latch& ready) noexcept {
  dds_link_impl::thread_setup("dds-receive", s_.thread_priority);
  constexpr int kBatch = 16;
  std::vector<syncplc_NodeSample> buf(kBatch);
  void* ptrs[kBatch];
  for (int j = 0; j < kBatch; ++j) ptrs[j] = &buf[static_cast<std::size_t>(j)];
  dds_sample_info_t infos[kBatch];
  struct State {
    std::uint32_t layout = 0;
    SubscriptionIntake intake;
  };
  std::vector<State> st(s_.subscribe.size());
  for (std::size_t i = 0; i < st.size(); ++i) st[i].layout = layout_word(s_.subscribe[i].topic, s_.subscribe[i].values);
  // Injected delay: each subscription's samples wait in a delay line of
  // fixed size (enough for the delay at one sample a millisecond, and more).
  struct Held {
    syncplc_NodeSample sample;
    dds_instance_handle_t writer;
  };
  const Injection& inj = s_.inject;
  const std::size_t hold = inj.delay_ns > 0 ? static_cast<std::size_t>(inj.delay_ns / 1'000'000) * 2 + 64 : 0;
  std::vector<DelayLine<Held>> delayed(s_.subscribe.size(), DelayLine<Held>(hold));
  std::mt19937_64 rng(inj.seed);
  std::bernoulli_distribution drop(inj.loss);

  // A sample that passed the injection (subscription_intake.hpp).
  auto accept = [&](std::size_t i, const syncplc_NodeSample& m, dds_instance_handle_t writer) {
    count(st[i].intake.accept(subs_[i], writer, m.scan, m.started_ns, m.values, s_.subscribe[i].values));
  };

  std::vector<dds_attach_t> triggered(s_.subscribe.size() + 1);
  ready.count_down();
  while (!stop_.load(std::memory_order_acquire)) {
    // Sleep until data, the stop guard, or the next held sample is due.
    dds_duration_t timeout = DDS_MSECS(100);
    const std::int64_t now = monotonic_ns();
    for (const auto& d : delayed)
      if (!d.empty()) timeout = std::min<dds_duration_t>(timeout, std::max<std::int64_t>(0, d.next_due() - now));
    const dds_return_t n = dds_waitset_wait(waitset_, triggered.data(), triggered.size(), timeout);
    if (n < 0) break;
    for (std::size_t i = 0; i < readers_.size(); ++i) {
      const auto& sub = s_.subscribe[i];
      for (;;) {
        const dds_return_t k = dds_take(readers_[i], ptrs, infos, kBatch, kBatch);
        if (k <= 0) break;
        for (int j = 0; j < k; ++j) {
          if (!infos[j].valid_data) continue;
          const syncplc_NodeSample& m = buf[static_cast<std::size_t>(j)];
          if (m.layout != st[i].layout || m.count != sub.values) {
            counters_.mismatched.fetch_add(1, std::memory_order_relaxed);
            continue;
          }
          if (inj.loss > 0 && drop(rng)) {
            counters_.injected_lost.fetch_add(1, std::memory_order_relaxed);
            continue;
          }
          if (inj.delay_ns > 0) {
            if (delayed[i].push(Held{m, infos[j].publication_handle}, monotonic_ns() + inj.delay_ns))
              counters_.injected_lost.fetch_add(1, std::memory_order_relaxed);  // the delay line was full
            continue;
          }
          accept(i, m, infos[j].publication_handle);
        }
      }
    }
    const std::int64_t after = monotonic_ns();
    for (std::size_t i = 0; i < delayed.size(); ++i)
      while (const Held* h = delayed[i].pop_due(after)) accept(i, h->sample, h->writer);
  }
}

}  // namespace syncplc::dds
