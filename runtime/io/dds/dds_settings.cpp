#include "runtime/io/dds/dds_settings.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <set>

#include "runtime/io/driver_config.hpp"

namespace syncplc::dds {
namespace dds_settings_read {

bool is_name(const std::string& s) {
  if (s.empty() || s.size() > 48) return false;
  if (!(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// A name (node, topic): letters, digits and _, not starting with a digit, at most 48.
bool name_at(DriverConfig& c, const ConfigNode* n, const std::string& what, std::string& out) {
  if (!n || !n->is_scalar() || !is_name(n->scalar)) {
    c.error(n ? n->loc : SourceLoc{}, what + " must be a name: letters, digits and _, at most 48, not starting with a digit");
    return false;
  }
  out = n->scalar;
  return true;
}

// Each returns false when one of its items had an error (reported).
bool read_publications(DriverConfig& c, DriverSetup& setup, const ConfigNode& list, DdsSettings& s) {
  if (!list.is_list()) {
    c.error(list.loc, "publish is a list of {topic, values}");
    return false;
  }
  bool ok = true;
  for (const auto& item : list.items) {
    auto pc = DriverConfig::section(item, setup, "publish", {"topic", "values"});
    Publication p;
    if (!pc.ok() || !name_at(c, item.find("topic"), "publish: topic", p.topic)) {
      ok = false;
      continue;
    }
    p.values = static_cast<std::uint32_t>(pc.integer("values", 1, 1, kMaxValues));
    if (pc.ok()) s.publish.push_back(p);
    else ok = false;
  }
  return ok;
}

void read_safe(DriverConfig& c, const ConfigNode& n, Subscription& sub) {
  sub.safe.assign(sub.values, 0.0);
  if (n.is_scalar()) {
    const double v = c.number_at(n, "safe", "");
    std::fill(sub.safe.begin(), sub.safe.end(), v);
  } else if (n.is_list() && n.items.size() == sub.values) {
    for (std::size_t i = 0; i < n.items.size(); ++i) sub.safe[i] = c.number_at(n.items[i], "safe", "");
  } else {
    c.error(n.loc, "safe: one value for every element, or a list of " + std::to_string(sub.values));
  }
}

bool read_subscriptions(DriverConfig& c, DriverSetup& setup, const ConfigNode& list, DdsSettings& s) {
  if (!list.is_list()) {
    c.error(list.loc, "subscribe is a list of {topic, values, stale_after, reaction, safe}");
    return false;
  }
  bool ok = true;
  for (const auto& item : list.items) {
    auto sc = DriverConfig::section(item, setup, "subscribe", {"topic", "values", "stale_after", "reaction", "safe"});
    Subscription sub;
    if (!sc.ok() || !name_at(c, item.find("topic"), "subscribe: topic", sub.topic)) {
      ok = false;
      continue;
    }
    sub.values = static_cast<std::uint32_t>(sc.integer("values", 1, 1, kMaxValues));
    sub.stale_after = static_cast<std::uint32_t>(sc.integer("stale_after", 0, 0, 1'000'000));
    const std::string r = sc.choice("reaction", {"hold", "safe", "stop"}, "hold");
    sub.reaction = r == "safe" ? StaleReaction::Safe : r == "stop" ? StaleReaction::Stop : StaleReaction::Hold;
    sub.safe.assign(sub.values, 0.0);
    if (const ConfigNode* n = item.find("safe")) read_safe(sc, *n, sub);
    if (sc.ok()) s.subscribe.push_back(sub);
    else ok = false;
  }
  return ok;
}

}  // namespace dds_settings_read

bool read_dds_settings(const ConfigNode& entry, DriverSetup& setup, DdsSettings& s) {
  using namespace dds_settings_read;
  DriverConfig c(entry, setup, "dds",
                 {"node", "domain", "peers", "interface", "shared_memory", "qos", "startup_check", "inject", "thread_priority", "publish", "subscribe"});
  if (!c.has("node")) c.error(entry.loc, "dds: node is required (this node's name)");
  else name_at(c, c.node("node"), "node", s.node);
  s.domain = static_cast<std::uint32_t>(c.integer("domain", 0, 0, 230));
  if (const ConfigNode* p = c.node("peers")) {
    if (!p->is_list()) c.error(p->loc, "peers is a list of addresses, e.g. [127.0.0.1, 10.0.0.2]");
    else
      for (const auto& a : p->items) {
        if (!a.is_scalar() || a.scalar.empty() || a.scalar.size() > 253 ||
            a.scalar.find_first_of("<>&\"' ") != std::string::npos)
          c.error(a.loc, "peers: '" + a.scalar + "' is not an address or host name");
        else s.peers.push_back(a.scalar);
      }
  }
  if (const ConfigNode* i = c.node("interface")) {
    if (!i->is_scalar() || i->scalar.empty() || i->scalar.size() > 64 ||
        i->scalar.find_first_of("<>&\"' ") != std::string::npos)
      c.error(i->loc, "interface: a network interface's name or address");
    else s.interface = i->scalar;
  }
  s.shared_memory = c.boolean("shared_memory", false);
  s.startup_check_ns = c.duration_ns("startup_check", 2'000'000'000, 0, 60'000'000'000);
  s.thread_priority = static_cast<int>(c.integer("thread_priority", 1, 0, 99));
  bool sections_ok = true;
  if (const ConfigNode* q = c.node("qos")) {
    auto qc = DriverConfig::section(*q, setup, "qos", {"reliability", "deadline", "liveliness"});
    s.reliability = qc.choice("reliability", {"best_effort", "reliable"}, "best_effort") == "reliable"
                        ? Reliability::Reliable
                        : Reliability::BestEffort;
    s.deadline_ns = qc.duration_ns("deadline", 0, 0, 3'600'000'000'000);
    s.liveliness_ns = qc.duration_ns("liveliness", 0, 0, 3'600'000'000'000);
    sections_ok &= qc.ok();
  }
  if (const ConfigNode* q = c.node("inject")) {
    auto ic = DriverConfig::section(*q, setup, "inject", {"loss", "delay", "seed"});
    s.inject.loss = ic.number("loss", "", 0.0, 0.0, 1.0);
    s.inject.delay_ns = ic.duration_ns("delay", 0, 0, 10'000'000'000);
    s.inject.seed = static_cast<std::uint64_t>(ic.integer("seed", static_cast<std::int64_t>(setup.seed()), 0, INT64_MAX));
    sections_ok &= ic.ok();
  }
  if (const ConfigNode* p = c.node("publish")) sections_ok &= read_publications(c, setup, *p, s);
  if (const ConfigNode* p = c.node("subscribe")) sections_ok &= read_subscriptions(c, setup, *p, s);
  if (s.publish.empty() && s.subscribe.empty() && c.ok() && sections_ok)
    c.error(entry.loc, "dds: nothing to publish or subscribe to");
  // Channel names must not collide: TOPIC and TOPIC_ok, _age, _lost, _late, _scan, _reaction.
  std::set<std::string> names;
  auto claim = [&](const std::string& n, const ConfigNode* where) {
    if (!names.insert(n).second) c.error(where ? where->loc : entry.loc, "dds: two channels would be named '" + n + "'");
  };
  for (const auto& p : s.publish) claim(p.topic, c.node("publish"));
  for (const auto& sub : s.subscribe) {
    claim(sub.topic, c.node("subscribe"));
    for (const char* suffix : {"_ok", "_age", "_lost", "_late", "_scan", "_reaction", "_phase"}) claim(sub.topic + suffix, c.node("subscribe"));
  }
  return c.ok() && sections_ok;
}

std::string wire_topic(const std::string& topic) { return "syncplc_" + topic; }

std::uint32_t layout_word(const std::string& topic, std::uint32_t values) {
  std::uint32_t h = 2166136261u;
  auto mix = [&](unsigned char b) {
    h ^= b;
    h *= 16777619u;
  };
  for (const char* p = "syncplc node sample 1/"; *p; ++p) mix(static_cast<unsigned char>(*p));
  for (char ch : topic) mix(static_cast<unsigned char>(ch));
  for (int i = 0; i < 4; ++i) mix(static_cast<unsigned char>(values >> (8 * i)));
  return h;
}

}  // namespace syncplc::dds
