#include "runtime/io/dds/dds_driver.hpp"

#include <atomic>
#include <memory>

#include "runtime/core/histogram.hpp"
#include "runtime/core/monotonic_clock.hpp"
#include "runtime/io/dds/dds_link.hpp"
#include "runtime/io/dds/dds_settings.hpp"
#include "runtime/io/dds/subscription_latch.hpp"
#include "runtime/io/dds/virtual_link.hpp"
#include "runtime/io/safe_output_latch.hpp"

namespace syncplc {
namespace dds_driver_impl {

using namespace syncplc::dds;

// Status channels of a subscription, after its values channel.
enum : int { kOk = 1, kAge, kLost, kLate, kScan, kReaction, kPhase, kFresh };

class DdsDriver final : public IoDriver {
 public:
  // bus: the simulated network of virtual time; nullptr: Cyclone DDS.
  DdsDriver(DdsSettings s, std::shared_ptr<VirtualBus> bus, std::int64_t period_ns, std::uint64_t seed)
      : s_(std::move(s)), virtual_(bus != nullptr) {
    if (bus) link_ = std::make_unique<VirtualLink>(s_, std::move(bus), period_ns, seed);
    else link_ = std::make_unique<DdsLink>(s_);
    for (const auto& p : s_.publish) {
      pub_channel_.push_back(static_cast<int>(channels_.size()));
      channels_.push_back({p.topic, PinDir::Out, IecType::LREAL, p.values, "", "published: one sample per scan"});
    }
    for (const auto& sub : s_.subscribe) {
      sub_channel_.push_back(static_cast<int>(channels_.size()));
      channels_.push_back({sub.topic, PinDir::In, IecType::LREAL, sub.values, "", "the newest sample's values"});
      channels_.push_back({sub.topic + "_ok", PinDir::In, IecType::BOOL, 1, "", "a sample arrived within stale_after scans"});
      channels_.push_back({sub.topic + "_age", PinDir::In, IecType::UDINT, 1, "", "scans since the newest sample arrived"});
      channels_.push_back({sub.topic + "_lost", PinDir::In, IecType::UDINT, 1, "", "samples that never arrived, since open"});
      channels_.push_back({sub.topic + "_late", PinDir::In, IecType::UDINT, 1, "", "samples that arrived after a newer one"});
      channels_.push_back({sub.topic + "_scan", PinDir::In, IecType::ULINT, 1, "", "the publisher's scan of the values"});
      channels_.push_back({sub.topic + "_reaction", PinDir::In, IecType::BOOL, 1, "", "stale past stale_after: the reaction applies"});
      channels_.push_back({sub.topic + "_phase", PinDir::In, IecType::LREAL, 1, "us",
                           "this scan's start minus the publisher's nearest scan start (real time)"});
      channels_.push_back({sub.topic + "_fresh", PinDir::In, IecType::BOOL, 1, "",
                           "a new sample was taken at this scan (an estimator's valid input)"});
    }
    ok_ = std::make_unique<std::atomic<bool>[]>(s_.subscribe.size());
    for (const auto& p : s_.publish) last_out_.emplace_back(p.values, Cell{});
  }

  const std::vector<DriverChannel>& channels() const override { return channels_; }

  void bind(const std::vector<Cell*>& cells) override {
    cells_ = cells;
    latches_.clear();
    for (const auto& sub : s_.subscribe) latches_.emplace_back(sub, make_subscription_texts(name(), sub));
  }

  bool open(std::string* error) override {
    for (auto& l : latches_) l.reset();
    for (std::size_t i = 0; i < s_.subscribe.size(); ++i) ok_[i].store(false, std::memory_order_relaxed);
    safe_.reset();
    phase_.reset();
    last_scan_ = 0;
    return link_->open(error);
  }

  void latch_inputs(const ScanContext& ctx) noexcept override {
    // When this scan began (a vDSO clock read, no system call): sent with
    // the samples, compared with the publishers' starts.
    started_ = ctx.virtual_time ? 0 : realtime_ns();
    link_->poll(ctx.now_ns);
    for (std::size_t i = 0; i < s_.subscribe.size(); ++i) {
      const int ch = sub_channel_[i];
      const SubscriptionStatus& st = latches_[i].latch(link_->subscription(i).acquire(), ctx, cell(ch), started_);
      if (st.fresh && st.has_phase) phase_.record(st.phase_ns < 0 ? -st.phase_ns : st.phase_ns);
      if (Cell* c = cell(ch + kPhase)) c->set<double>(static_cast<double>(st.phase_ns) / 1000.0);
      ok_[i].store(st.ok, std::memory_order_relaxed);
      if (Cell* c = cell(ch + kOk)) c->set<bool>(st.ok);
      if (Cell* c = cell(ch + kAge)) c->set<std::uint32_t>(st.age);
      if (Cell* c = cell(ch + kLost)) c->set<std::uint32_t>(st.lost);
      if (Cell* c = cell(ch + kLate)) c->set<std::uint32_t>(st.late);
      if (Cell* c = cell(ch + kScan)) c->set<std::uint64_t>(st.scan);
      if (Cell* c = cell(ch + kReaction)) c->set<bool>(st.reacting);
      if (Cell* c = cell(ch + kFresh)) c->set<bool>(st.fresh);
    }
  }

  void write_outputs(const ScanContext& ctx) noexcept override {
    if (!safe_.begin_write()) return;  // held in the safe state
    last_scan_ = ctx.scan;
    for (std::size_t i = 0; i < s_.publish.size(); ++i) {
      if (const Cell* c = cell(pub_channel_[i])) std::copy(c, c + s_.publish[i].values, last_out_[i].begin());
      publish(i, ctx.scan, ctx.realtime_ns ? ctx.realtime_ns : ctx.now_ns);
    }
    safe_.end_write();
    link_->hand_over();
  }

  bool write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept override {
    if (!safe_.engage()) return false;
    // The safe values go out as one more sample of each publication, the
    // scan after the last one written, so that subscribers take it as new.
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t i = 0; i < s_.publish.size(); ++i)
        if (outputs[k].channel == pub_channel_[i] && outputs[k].element < s_.publish[i].values)
          last_out_[i][outputs[k].element] = outputs[k].value;
    for (std::size_t i = 0; i < s_.publish.size(); ++i) publish(i, last_scan_ + 1, last_time_);
    link_->hand_over();
    return true;
  }

  void close() noexcept override { link_->close(); }

  bool input_ok(int channel) const noexcept override {
    for (std::size_t i = 0; i < sub_channel_.size(); ++i)
      if (channel == sub_channel_[i]) return ok_[i].load(std::memory_order_relaxed);
    return true;
  }

  bool read_output(int channel, Cell* values) const override {
    for (std::size_t i = 0; i < pub_channel_.size(); ++i)
      if (channel == pub_channel_[i]) {
        std::copy(last_out_[i].begin(), last_out_[i].end(), values);
        return true;
      }
    return false;
  }

  std::string summary() const override {
    std::string t = "node " + s_.node + (virtual_ ? ", virtual time: the system's simulated bus" : ", DDS domain " + std::to_string(s_.domain));
    if (s_.inject.on())
      t += ", INJECTING loss " + std::to_string(s_.inject.loss) + " and delay " + std::to_string(s_.inject.delay_ns / 1000) + " us";
    if (!s_.peers.empty()) {
      t += ", peers";
      for (const auto& p : s_.peers) t += " " + p;
    }
    for (const auto& p : s_.publish) t += "; publishes " + p.topic + " (" + std::to_string(p.values) + ")";
    for (const auto& sub : s_.subscribe)
      t += "; subscribes " + sub.topic + " (" + std::to_string(sub.values) + ", stale after " + std::to_string(sub.stale_after) +
           (sub.stale_after == 1 ? " scan: " : " scans: ") +
           (sub.reaction == StaleReaction::Hold ? "hold" : sub.reaction == StaleReaction::Safe ? "safe" : "stop") + ")";
    return t;
  }

  std::vector<std::pair<std::string, double>> counters() const override {
    const LinkCounters& c = link_->counters();
    const Histogram::Summary ph = phase_.summary();
    auto v = [](const std::atomic<std::uint64_t>& a) { return static_cast<double>(a.load(std::memory_order_relaxed)); };
    return {{"samples_sent", v(c.sent)},         {"write_errors", v(c.write_errors)},
            {"samples_received", v(c.received)}, {"samples_lost", v(c.lost)},
            {"samples_late", v(c.late)},         {"samples_mismatched", v(c.mismatched)},
            {"writers_changed", v(c.writers_changed)}, {"samples_dropped_by_injection", v(c.injected_lost)},
            {"phase_samples", static_cast<double>(ph.count)}, {"phase_abs_p50_us", static_cast<double>(ph.p50) / 1000.0},
            {"phase_abs_p99_us", static_cast<double>(ph.p99) / 1000.0}, {"phase_abs_max_us", static_cast<double>(ph.max) / 1000.0}};
  }

 private:
  Cell* cell(int ch) const noexcept {
    return ch >= 0 && static_cast<std::size_t>(ch) < cells_.size() ? cells_[static_cast<std::size_t>(ch)] : nullptr;
  }
  void publish(std::size_t i, std::uint64_t scan, std::int64_t time) noexcept {
    TripleBuffer& b = link_->publication(i);
    Cell* out = b.back();
    out[PublicationCells::kScan].set<std::uint64_t>(scan);
    out[PublicationCells::kTime].set<std::int64_t>(time);
    out[PublicationCells::kStarted].set<std::int64_t>(started_);
    // A channel of n values is n LREAL cells.
    std::copy(last_out_[i].begin(), last_out_[i].end(), out + PublicationCells::kValues);
    b.publish();
    last_time_ = time;
  }

  DdsSettings s_;
  bool virtual_;
  std::unique_ptr<Link> link_;
  std::vector<DriverChannel> channels_;
  std::vector<int> pub_channel_, sub_channel_;
  std::vector<Cell*> cells_;
  std::vector<SubscriptionLatch> latches_;
  std::unique_ptr<std::atomic<bool>[]> ok_;
  std::vector<std::vector<Cell>> last_out_;
  SafeOutputLatch safe_;
  std::uint64_t last_scan_ = 0;
  std::int64_t started_ = 0;  // this scan's start on CLOCK_REALTIME (latch_inputs); 0 in virtual time
  Histogram phase_;           // |phase| of fresh samples, ns (docs/dds.md, "One grid for all nodes")
  std::int64_t last_time_ = 0;
};

}  // namespace dds_driver_impl

DriverTypeInfo dds_driver_type() {
  DriverTypeInfo t;
  t.name = "dds";
  t.doc =
      "Nodes over Cyclone DDS: node, domain, peers (unicast discovery, multicast off), interface, shared_memory, "
      "qos {reliability (best_effort, reliable), deadline, liveliness}; publish [{topic, values}] as one sample per "
      "scan; subscribe [{topic, values, stale_after (scans), reaction (hold, safe, stop), safe}]. Channels: TOPIC, "
      "and per subscription TOPIC_ok, TOPIC_age (scans), TOPIC_lost, TOPIC_late, TOPIC_scan, TOPIC_reaction, TOPIC_phase (us), TOPIC_fresh. "
      "docs/dds.md.";
  t.create = [](const ConfigNode& node, DriverSetup& setup) -> std::unique_ptr<IoDriver> {
    dds::DdsSettings s;
    if (!dds::read_dds_settings(node, setup, s)) return nullptr;
    std::shared_ptr<VirtualBus> bus;
    if (setup.virtual_time()) {
      bus = setup.bus();
      // A project simulated on its own: its subscriptions see only what it
      // publishes itself.
      if (!bus) bus = std::make_shared<VirtualBus>();
    }
    return std::make_unique<dds_driver_impl::DdsDriver>(std::move(s), std::move(bus), setup.task_period_ns(), setup.seed());
  };
  return t;
}

}  // namespace syncplc
