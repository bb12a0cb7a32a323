// Reading the drivers: section: each driver created by its type's factory
// from its settings (after --set driver.key=value), its channels bound to tags.
#include <algorithm>

#include "runtime/core/units.hpp"
#include "runtime/project/stages.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc {
namespace {

// What a driver's factory sees of the project.
class Setup final : public DriverSetup {
 public:
  Setup(std::int64_t period, std::uint64_t seed, const LoadOptions& o, Diagnostics& d)
      : period_(period), seed_(seed), o_(o), d_(d) {}
  std::int64_t task_period_ns() const override { return period_; }
  std::uint64_t seed() const override { return seed_; }
  void error(const SourceLoc& where, const std::string& message) override { d_.error(where, message); }
  bool virtual_time() const override { return o_.virtual_time; }
  std::shared_ptr<VirtualBus> bus() const override { return o_.bus; }

 private:
  std::int64_t period_;
  std::uint64_t seed_;
  const LoadOptions& o_;
  Diagnostics& d_;
};

}  // namespace

// --set driver.key=value and driver.key.subkey=value change a driver's settings
// before it is created, as if the project file said so (the value's errors
// are reported at "command line").
std::set<std::string> override_driver_settings(ConfigNode& drivers, const LoadOptions& opts, Diagnostics& diags) {
  std::set<std::string> driver_overrides;
  if (!drivers.is_list()) return driver_overrides;
  for (const auto& o : opts.overrides) {
    for (auto& dn : drivers.items) {
      const ConfigNode* nm = dn.is_map() ? dn.find("name") : nullptr;
      if (!nm || nm->scalar != o.instance || o.param.empty()) continue;
      driver_overrides.insert(o.instance);
      ConfigNode* at = &dn;
      std::string path = o.param;
      SourceLoc cli{"command line", 0, 0};
      bool ok = true;
      while (ok) {
        auto dot = path.find('.');
        std::string key = path.substr(0, dot);
        // A driver's own name, type and task, and a list item's name (it is how
        // --set finds the item), are not settings; an item's other keys are
        // (a group's type: io.groups.g.type=DINT).
        if (key == "name" || (at == &dn && (key == "type" || key == "task"))) {
          diags.error(cli, "--set " + o.instance + "." + o.param + ": " +
                               (at == &dn ? "a driver's " + key : std::string("an item's name")) + " cannot be overridden");
          ok = false;
          break;
        }
        ConfigNode* child = nullptr;
        for (auto& [k, v] : at->map)
          if (k == key) child = &v;
        // A list of named items (a modbus_client's devices, groups) is entered
        // by an item's name: io.devices.d1.port=5021.
        if (child && child->is_list() && dot != std::string::npos) {
          path = path.substr(dot + 1);
          dot = path.find('.');
          const std::string item = path.substr(0, dot);
          ConfigNode* named = nullptr;
          for (auto& it : child->items) {
            const ConfigNode* in = it.is_map() ? it.find("name") : nullptr;
            if (in && in->scalar == item) named = &it;
          }
          if (!named || dot == std::string::npos) {
            diags.error(cli, "--set " + o.instance + "." + o.param + ": " +
                                 (named ? "name a setting of " + key + " item " + item
                                        : key + " has no item named '" + item + "'"));
            ok = false;
            break;
          }
          at = named;
          path = path.substr(dot + 1);
          continue;
        }
        if (!child) {
          at->map.emplace_back(key, ConfigNode{});
          child = &at->map.back().second;
        }
        if (dot == std::string::npos) {
          // A flow list replaces a list setting: net.peers=[10.0.0.1, 10.0.0.2]
          // (one node's project on several machines, each with its own peers).
          if (o.value.size() >= 2 && o.value.front() == '[' && o.value.back() == ']') {
            Diagnostics list_errors;
            ConfigNode list = read_yaml_string(o.value, "command line", list_errors);
            for (const auto& e : list_errors.list()) diags.error(cli, "--set " + o.instance + "." + o.param + ": " + e.message);
            if (!list_errors.empty()) {
              ok = false;
              break;
            }
            *child = std::move(list);
            break;
          }
          child->kind = ConfigNode::Kind::Scalar;
          child->scalar = o.value;
          child->items.clear();
          child->map.clear();
          child->loc = cli;
          break;
        }
        if (!child->is_map()) {
          if (child->kind != ConfigNode::Kind::Null) {
            diags.error(cli, "--set " + o.instance + "." + o.param + ": " + key + " is not a map of settings");
            ok = false;
            break;
          }
          child->kind = ConfigNode::Kind::Map;
          child->loc = cli;
        }
        at = child;
        path = path.substr(dot + 1);
      }
    }
  }
  return driver_overrides;
}

void read_drivers(const ConfigNode& n, const DriverRegistry& drivers, const LoadOptions& opts, Declarations& p,
                  Diagnostics& diags) {
  if (!n.is_list()) { diags.error(n.loc, "drivers: expected a list"); return; }
  for (const auto& dn : n.items) {
    if (!dn.is_map()) { diags.error(dn.loc, "a driver is a map {name, type, task, bind, ...}"); continue; }
    DriverDecl dd;
    dd.loc = dn.loc;
    const ConfigNode* nm = dn.find("name");
    const ConfigNode* ty = dn.find("type");
    const ConfigNode* tk = dn.find("task");
    if (!nm || nm->scalar.empty()) { diags.error(dn.loc, "driver without a name"); continue; }
    dd.name = nm->scalar;
    if (!is_identifier(dd.name)) { diags.error(nm->loc, "driver name '" + dd.name + "' is not an identifier"); continue; }
    if (p.names.count(dd.name)) { diags.error(nm->loc, "duplicate name '" + dd.name + "' (first defined at " + p.names[dd.name].text() + ")"); continue; }
    p.names[dd.name] = nm->loc;
    if (!ty) { diags.error(dn.loc, "driver " + dd.name + " has no type"); continue; }
    const DriverTypeInfo* info = drivers.find(ty->scalar);
    if (!info) {
      std::string names;
      for (const auto& x : drivers.names()) names += (names.empty() ? "" : ", ") + x;
      diags.error(ty->loc, "unknown driver type '" + ty->scalar + "' (" + names + ")");
      continue;
    }
    dd.type = ty->scalar;
    if (!tk) { if (p.tasks.size() == 1) dd.task = 0; else { diags.error(dn.loc, "driver " + dd.name + " has no task"); continue; } }
    else if ((dd.task = p.task_index(tk->scalar)) < 0) { diags.error(tk->loc, "unknown task '" + tk->scalar + "'"); continue; }
    Setup setup(p.tasks[static_cast<std::size_t>(dd.task)].cfg.period_ns, mix_seed(p.seed, dd.name), opts, diags);
    std::size_t before = diags.size();
    dd.driver = info->create(dn, setup);
    dd.settings = dd.type + "|" + std::to_string(p.tasks[static_cast<std::size_t>(dd.task)].cfg.period_ns) + "|" +
                  std::to_string(mix_seed(p.seed, dd.name)) + "|" + canonical_text(dn, "bind");
    if (!dd.driver) {
      if (diags.size() == before) diags.error(dn.loc, "driver " + dd.name + " could not be created");
      continue;
    }
    dd.driver->set_name(dd.name);
    const auto& chans = dd.driver->channels();
    dd.channel_tag.assign(chans.size(), -1);
    dd.channel_loc.assign(chans.size(), dn.loc);
    if (const ConfigNode* bind = dn.find("bind")) {
      if (!bind->is_map()) diags.error(bind->loc, "bind: expected a map of channel: tag");
      else
        for (const auto& entry : bind->map) {
          // Named, not a structured binding: clang 14 cannot capture those in a lambda.
          const std::string& ch = entry.first;
          const ConfigNode& tagn = entry.second;
          auto it = std::find_if(chans.begin(), chans.end(), [&](const DriverChannel& c) { return c.name == ch; });
          if (it == chans.end()) { diags.error(tagn.loc, "driver " + dd.name + " has no channel '" + ch + "'"); continue; }
          int ti = p.tag_index(tagn.scalar);
          if (ti < 0 && p.failed_names.count(tagn.scalar)) continue;
          if (ti < 0) { diags.error(tagn.loc, "unknown tag '" + tagn.scalar + "'"); continue; }
          const Tag& tg = p.tags[static_cast<std::size_t>(ti)].tag;
          if (tg.type != it->type || tg.length != it->length)
            diags.error(tagn.loc, "type mismatch: channel " + dd.name + "." + ch + " is " + std::string(type_name(it->type)) +
                                   (it->length > 1 ? "[" + std::to_string(it->length) + "]" : "") + ", tag " + tg.name + " is " +
                                   std::string(type_name(tg.type)) + (tg.length > 1 ? "[" + std::to_string(tg.length) + "]" : ""));
          // A channel copies its value as it is, as a connection does: the
          // tag must mean the channel's unit (a tag without one takes any).
          if (const UnitCopy fit = unit_copy(it->unit, tg.unit); fit != UnitCopy::Fits)
            diags.error(tagn.loc, "unit mismatch: channel " + dd.name + "." + ch + " is in " + it->unit + ", tag " + tg.name +
                                   " in " + tg.unit +
                                   (fit == UnitCopy::OtherDimension ? " (another dimension)"
                                                                    : " (the driver copies the value: give the tag the "
                                                                      "channel's unit, or scale it with a MUL block)"));
          auto ci = static_cast<std::size_t>(it - chans.begin());
          dd.channel_tag[ci] = ti;
          dd.channel_loc[ci] = tagn.loc;
        }
    }
    p.drivers.push_back(std::move(dd));
  }
}

}  // namespace syncplc
