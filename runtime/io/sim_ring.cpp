#include "runtime/io/sim_ring.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "runtime/io/driver_config.hpp"

namespace syncplc {

SimRingDriver::SimRingDriver(SimRingConfig cfg) : cfg_(std::move(cfg)), rng_(cfg_.seed), frame_loss_(cfg_.loss) {
  const std::uint32_t n = cfg_.nodes, w = cfg_.command_words;
  channels_ = {
      {"master_cmd", PinDir::Out, IecType::LREAL, n * w, "",
       "x_d(k+1) for every axis (command_words values an axis, axis after axis), sent by the master in frame k"},
      {"err_tx", PinDir::Out, IecType::LREAL, n, "", "element i: node i's feedback error e_i(k), written into frame k"},
      {"cmd", PinDir::In, IecType::LREAL, n * w, "", "the command words node i received (held when lost)"},
      {"cmd_valid", PinDir::In, IecType::BOOL, n, "", "element i: node i received the last frame in time"},
  };
  for (std::uint32_t k = 1; k <= n; ++k) {
    const std::string p = "node" + std::to_string(k);
    channels_.push_back({p + "_err", PinDir::In, IecType::LREAL, n, "",
                         "errors e_1..e_" + std::to_string(k - 1) + " as node " + std::to_string(k) +
                             " received them, one frame late (elements from " + std::to_string(k) + " on are 0)"});
    channels_.push_back({p + "_err_valid", PinDir::In, IecType::BOOL, n, "", "which elements of " + p + "_err are fresh"});
  }
  channels_.push_back({"frames_sent", PinDir::In, IecType::ULINT, 1, "", "frames sent by the master"});
  channels_.push_back({"frames_lost", PinDir::In, IecType::ULINT, 1, "", "frames that did not reach every node"});
  channels_.push_back({"frames_late", PinDir::In, IecType::ULINT, 1, "", "frames that arrived after the deadline"});
  bound_.assign(channels_.size(), nullptr);
  link_loss_.assign(n, LossProcess(cfg_.loss));
  frame_cmd_.assign(static_cast<std::size_t>(n) * w, 0.0);
  frame_err_.assign(n, 0.0);
  received_.assign(n, 0);
  held_cmd_.assign(static_cast<std::size_t>(n) * w, 0.0);
  held_err_.assign(static_cast<std::size_t>(n) * n, 0.0);
  safe_cmd_.assign(frame_cmd_.size(), 0.0);
  safe_err_.assign(n, 0.0);
}

bool SimRingDriver::open(std::string*) {
  safe_.reset();
  safe_ready_.store(false, std::memory_order_release);
  safe_sent_ = false;
  return true;
}

bool SimRingDriver::write_safe_outputs(const SafeOutput* outputs, std::size_t n) noexcept {
  if (safe_ready_.load(std::memory_order_acquire)) return true;  // already in the safe state
  if (!safe_.engage()) return false;
  // After engage() the scan thread no longer writes the frame: values without
  // a safe value keep what the last frame carried. Sized at construction.
  std::copy(frame_cmd_.begin(), frame_cmd_.end(), safe_cmd_.begin());
  std::copy(frame_err_.begin(), frame_err_.end(), safe_err_.begin());
  for (std::size_t i = 0; i < n; ++i) {
    const auto& o = outputs[i];
    if (o.channel == kMasterCmd && o.element < safe_cmd_.size()) safe_cmd_[o.element] = o.value.get<double>();
    if (o.channel == kErrTx && o.element < safe_err_.size()) safe_err_[o.element] = o.value.get<double>();
  }
  safe_ready_.store(true, std::memory_order_release);
  return true;
}

void SimRingDriver::write_outputs(const ScanContext&) noexcept {
  if (!safe_.begin_write()) return;  // held in the safe state
  const std::uint32_t n = cfg_.nodes;
  for (std::size_t i = 0; i < frame_cmd_.size(); ++i)
    frame_cmd_[i] = bound_[kMasterCmd] ? bound_[kMasterCmd][i].get<double>() : 0.0;
  for (std::uint32_t i = 0; i < n; ++i) frame_err_[i] = bound_[kErrTx] ? bound_[kErrTx][i].get<double>() : 0.0;
  // Which nodes the frame reaches: a lost link cuts off every node after it.
  bool reach = true;
  if (cfg_.per_link) {
    for (std::uint32_t i = 0; i < n; ++i) {
      bool link_lost = link_loss_[i].lost(rng_);  // drawn for every link, so patterns do not depend on earlier links
      reach = reach && !link_lost;
      received_[i] = reach;
    }
  } else {
    reach = !frame_loss_.lost(rng_);
    for (std::uint32_t i = 0; i < n; ++i) received_[i] = reach;
  }
  const bool lost = !received_[n - 1];
  const bool late = !lost && cfg_.late > 0 && rng_.chance(cfg_.late);
  if (late)
    for (std::uint32_t i = 0; i < n; ++i) received_[i] = 0;
  ++sent_;
  lost_ += lost;
  late_ += late;
  frame_pending_ = true;
  safe_.end_write();
}

void SimRingDriver::latch_inputs(const ScanContext&) noexcept {
  const std::uint32_t n = cfg_.nodes, w = cfg_.command_words;
  if (!safe_sent_ && safe_ready_.load(std::memory_order_acquire)) {  // the safe frame reaches every node
    std::copy(safe_cmd_.begin(), safe_cmd_.end(), frame_cmd_.begin());
    std::copy(safe_err_.begin(), safe_err_.end(), frame_err_.begin());
    for (std::uint32_t i = 0; i < n; ++i) received_[i] = 1;
    ++sent_;
    frame_pending_ = true;
    safe_sent_ = true;
  }
  for (std::uint32_t i = 0; i < n; ++i) {
    const bool fresh = frame_pending_ && received_[i];
    if (fresh) {
      for (std::uint32_t k = 0; k < w; ++k) held_cmd_[i * w + k] = frame_cmd_[i * w + k];
      for (std::uint32_t j = 0; j < i; ++j) held_err_[static_cast<std::size_t>(i) * n + j] = frame_err_[j];
    }
    if (Cell* c = bound_[kCmd])
      for (std::uint32_t k = 0; k < w; ++k) c[i * w + k].set<double>(held_cmd_[i * w + k]);
    if (Cell* c = bound_[kCmdValid]) c[i].set<bool>(fresh);
    Cell* e = bound_[static_cast<std::size_t>(node_err_channel(i))];
    Cell* v = bound_[static_cast<std::size_t>(node_err_channel(i)) + 1];
    for (std::uint32_t j = 0; j < n; ++j) {
      if (e) e[j].set<double>(j < i ? held_err_[static_cast<std::size_t>(i) * n + j] : 0.0);
      if (v) v[j].set<bool>(j < i && fresh);
    }
  }
  frame_pending_ = false;
  const auto k = static_cast<std::size_t>(counter_channel());
  if (Cell* c = bound_[k]) c->set<std::uint64_t>(sent_);
  if (Cell* c = bound_[k + 1]) c->set<std::uint64_t>(lost_);
  if (Cell* c = bound_[k + 2]) c->set<std::uint64_t>(late_);
}

std::vector<std::pair<std::string, double>> SimRingDriver::counters() const {
  return {{"frames_sent", static_cast<double>(sent_)},
          {"frames_lost", static_cast<double>(lost_)},
          {"frames_late", static_cast<double>(late_)}};
}

namespace {

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

}  // namespace

DriverTypeInfo sim_ring_driver_type() {
  DriverTypeInfo t;
  t.name = "sim_ring";
  t.doc =
      "Simulated real-time ring (paper 000 §4.1, Fig. 2): one lumped frame per cycle carries the master's x_d(k+1) "
      "and every node's error e_i(k); node k sees e_1..e_{k-1} one frame late. Keys: nodes (default 4); "
      "command_words (LREALs of command per axis: 1 = position, 3 = position, velocity, acceleration); loss: "
      "{model: none | bernoulli | gilbert_elliott, p, p_good_bad, p_bad_good, loss_good, loss_bad, scope: frame | "
      "link}; late (probability per frame); bus: {type: ethercat | ieee1394, bandwidth (Mbit/s), payload (bytes), "
      "overhead (bytes), hop_delay, gap_count, exec_time, alpha} — the bus time per cycle is checked against the "
      "period at load (paper 002 eqs. (1)-(11); paper 000 §6.2). Channels: master_cmd, err_tx (out); cmd, cmd_valid, "
      "node<k>_err, node<k>_err_valid, frames_sent, frames_lost, frames_late (in).";
  t.create = [](const ConfigNode& node, DriverSetup& setup) -> std::unique_ptr<IoDriver> {
    DriverConfig c(node, setup, "sim_ring", {"nodes", "command_words", "loss", "late", "bus"});
    SimRingConfig cfg;
    cfg.seed = setup.seed();
    cfg.nodes = static_cast<std::uint32_t>(c.integer("nodes", 4, 1, 64));
    cfg.command_words = static_cast<std::uint32_t>(c.integer("command_words", 1, 1, 8));
    cfg.late = c.number("late", "", 0.0, 0.0, 1.0);
    const int n = static_cast<int>(cfg.nodes);
    if (const ConfigNode* l = c.node("loss")) {
      if (!l->is_map()) {
        c.error(l->loc, "loss: expected a map {model, p, scope, ...}");
      } else {
        auto lc = DriverConfig::section(*l, setup, "loss", {"model", "p", "p_good_bad", "p_bad_good", "loss_good", "loss_bad", "scope"});
        std::string model = lc.choice("model", {"none", "bernoulli", "gilbert_elliott"}, "bernoulli");
        auto& L = cfg.loss;
        if (model == "bernoulli") {
          L.model = LossConfig::Model::Bernoulli;
          if (!lc.has("p")) lc.error(l->loc, "a bernoulli loss needs p (probability per frame or link, 0..1)");
          L.p = lc.number("p", "", 0.0, 0.0, 1.0);
        } else if (model == "gilbert_elliott") {
          L.model = LossConfig::Model::GilbertElliott;
          for (const char* k : {"p_good_bad", "p_bad_good"})
            if (!lc.has(k)) lc.error(l->loc, std::string("a gilbert_elliott loss needs ") + k);
          L.p_good_bad = lc.number("p_good_bad", "", 0.0, 0.0, 1.0);
          L.p_bad_good = lc.number("p_bad_good", "", 1.0, 0.0, 1.0);
          L.loss_good = lc.number("loss_good", "", 0.0, 0.0, 1.0);
          L.loss_bad = lc.number("loss_bad", "", 1.0, 0.0, 1.0);
        }
        cfg.per_link = lc.choice("scope", {"frame", "link"}, "frame") == "link";
        if (!lc.ok()) c.error(l->loc, "loss: see the errors above");
      }
    }
    // The bus: time per cycle against the period.
    const double period_us = static_cast<double>(setup.task_period_ns()) / 1000.0;
    std::string type = "ethercat";
    const ConfigNode* busn = c.node("bus");
    ConfigNode empty;
    empty.kind = ConfigNode::Kind::Map;
    empty.loc = node.loc;
    const ConfigNode& bn = busn ? *busn : empty;
    if (busn && !busn->is_map()) c.error(busn->loc, "bus: expected a map {type, bandwidth, payload, ...}");
    else {
      auto bc = DriverConfig::section(bn, setup, "bus",
                      {"type", "bandwidth", "payload", "overhead", "hop_delay", "gap_count", "exec_time", "alpha"});
      type = bc.choice("type", {"ethercat", "ieee1394"}, "ethercat");
      double bus_us = 0, limit_us = 0;
      std::string detail;
      if (type == "ethercat") {
        EthercatBus b;
        b.bandwidth = bc.number("bandwidth", "", 100, 1e-3, 1e6);
        b.overhead = bc.number("overhead", "", 12, 0, 1e6);
        b.hop_us = bc.number("hop_delay", "s", 0, 0, 1) * 1e6;
        // Paper 000 §6.2: 48 B for four nodes; 12 B a node (command, error, status).
        double payload = bc.number("payload", "", 12.0 * n, 0, 1e6);
        double alpha = bc.number("alpha", "", 1.0, 1e-3, 1.0);
        if (bc.has("gap_count") || bc.has("exec_time"))
          bc.error(bn.loc, "gap_count and exec_time belong to an ieee1394 bus");
        bus_us = ethercat_frame_us(b, n, payload);
        limit_us = alpha * period_us;
        detail = "ethercat " + fmt("%g", b.bandwidth) + " Mbit/s, " + fmt("%g", payload) + " B payload + " +
                 fmt("%g", b.overhead) + " B overhead";
      } else {
        Ieee1394Bus b;
        b.bandwidth = bc.number("bandwidth", "", 393.216, 1e-3, 1e6);
        b.overhead = bc.number("overhead", "", 20, 0, 1e6);
        b.gap_count = static_cast<int>(bc.integer("gap_count", 63, 1, 63));
        b.exec_us = bc.number("exec_time", "s", 0, 0, 1) * 1e6;
        b.alpha = bc.number("alpha", "", 0.5, 1e-3, 1.0);
        double payload = bc.number("payload", "", 8, 0, 1e6);  // bytes per node and transaction
        if (bc.has("hop_delay")) bc.error(bn.loc, "hop_delay belongs to an ethercat bus");
        bus_us = ieee1394_cycle_us(b, n, payload);
        limit_us = b.alpha * period_us;
        int nmax = ieee1394_max_nodes(b, period_us, payload);
        detail = "ieee1394 " + fmt("%g", b.bandwidth) + " Mbit/s, gap count " + std::to_string(b.gap_count) + ", " +
                 fmt("%g", payload) + " B per transaction, at most " + std::to_string(nmax) + " nodes (eq. (11))";
      }
      if (bc.ok() && bus_us > limit_us)
        c.error(busn ? busn->loc : node.loc,
                "the bus needs " + fmt("%.2f", bus_us) + " us per cycle, more than the " + fmt("%.2f", limit_us) +
                    " us the " + format_duration(setup.task_period_ns()) + " period leaves it (" + detail +
                    "): lengthen the period or carry fewer nodes");
      if (!bc.ok()) c.error(bn.loc, "bus: see the errors above");
      cfg.bus_summary = std::to_string(n) + " nodes, " + detail + ": bus time " + fmt("%.2f", bus_us) + " us per " +
                        format_duration(setup.task_period_ns()) + " cycle (" + fmt("%.1f", 100.0 * bus_us / period_us) +
                        " % of the period; limit " + fmt("%.0f", 100.0 * limit_us / period_us) + " %)";
    }
    if (!c.ok()) return nullptr;
    return std::make_unique<SimRingDriver>(std::move(cfg));
  };
  return t;
}

}  // namespace syncplc
