// The PLCopen axes (docs/http-api.md, "Axes"): every MC_AXIS instance with
// its live state for the HMI's faceplates, and the HMI's three commands on an
// axis. A command is a write of one of the axis's HMI pins (hmi_enable,
// hmi_reset) through its task's write queue, as tag writes go: nothing is
// locked or allocated in the scan, and the axis acts on it in the next scan.
#include "fblocks/plcopen/axis_block.hpp"
#include "fblocks/plcopen/axis_texts.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/live_values.hpp"

namespace syncplc::web {
namespace {

using plcopen::AxisState;

// The pins GET /axes reads of every axis, and the names it gives them.
struct ShownPin {
  int pin;
  const char* key;
};
constexpr ShownPin kShownPins[] = {
    {plcopen::kAxState, "state_code"},
    {plcopen::kAxPosition, "position"},
    {plcopen::kAxVelocity, "velocity"},
    {plcopen::kAxSetPosition, "set_position"},
    {plcopen::kAxFollowingError, "following_error"},
    {plcopen::kAxCommand, "command_code"},
    {plcopen::kAxCommandBlock, "command_block_index"},
    {plcopen::kAxErrorId, "error_id"},
    {plcopen::kAxPowered, "powered"},
    {plcopen::kAxHomed, "homed"},
    {plcopen::kAxRemainingScans, "remaining_scans"},
    {plcopen::kAxHmiEnable, "hmi_enable"},
};

bool is_axis(const BlockInstance& b) { return b.type && b.type->name == plcopen::kAxisType; }

// The axis instance named `name`, with its task; null when none.
struct AxisAt {
  Task* task = nullptr;
  const BlockInstance* block = nullptr;
};
AxisAt find_axis(Program& p, const std::string& name) {
  for (auto& t : p.tasks)
    for (const auto& b : t->blocks)
      if (b.name == name && is_axis(b)) return {t.get(), &b};
  return {};
}

// A program's connection writes the pin every scan: the HMI's write would be
// overwritten at once (a project may wire hmi_enable to a key switch).
bool pin_wired(const BlockInstance& b, int pin) {
  const std::uint32_t cell = b.pin_cell[static_cast<std::size_t>(pin)];
  for (const auto& c : b.copy_in)
    if (cell >= c.dst && cell < c.dst + c.n) return true;
  return false;
}

// The unit of the tag the axis's position output is wired to; "u" (the
// axis's user unit, docs/motion/plcopen.md) when none says.
std::string axis_unit(const Program& p, const Task& t, const BlockInstance& b) {
  const std::uint32_t out = b.pin_cell[plcopen::kAxPosition];
  for (const auto& c : b.copy_out)
    if (c.src == out)
      for (const auto& tag : p.tags)
        if (tag.owner == t.index() && c.dst >= tag.cell && c.dst < tag.cell + tag.length && !tag.unit.empty())
          return tag.unit;
  return "u";
}

// One pass over every axis: its values, or false when a pin's monitoring is
// only starting (ask again a period later).
bool read_axes(Program& p, std::uint64_t generation, const HiddenCells* hidden, nlohmann::json* axes) {
  *axes = nlohmann::json::array();
  for (auto& t : p.tasks) {
    for (const auto& b : t->blocks) {
      if (!is_axis(b)) continue;
      std::vector<std::string> refs;
      for (const auto& s : kShownPins) refs.push_back(b.name + "." + b.type->pins[static_cast<std::size_t>(s.pin)].name);
      LiveRefs live;
      live.set_refs(refs);
      const nlohmann::json tick = live.tick(p, generation, hidden);
      // A pin this reader may not see (wired to an hmi: none tag) is null;
      // an axis whose state it may not see is not shown.
      const bool has_errors = tick.contains("errors");
      if (has_errors && tick["errors"].contains(refs[0])) continue;
      nlohmann::json a{{"name", b.name},
                       {"task", t->config().name},
                       {"period_ns", t->config().period_ns},
                       {"unit", axis_unit(p, *t, b)}};
      for (std::size_t i = 0; i < refs.size(); ++i) {
        if (has_errors && tick["errors"].contains(refs[i])) {
          a[kShownPins[i].key] = nullptr;
          continue;
        }
        if (!tick["values"].contains(refs[i])) return false;
        a[kShownPins[i].key] = tick["values"][refs[i]];
      }
      // One task, one scan: the state's quality is every value's.
      a["quality"] = tick["quality"][refs[0]];
      const int state = a["state_code"].get<int>();
      a["state"] = plcopen::axis_state_name(static_cast<AxisState>(state));
      const int kind = a["command_code"].is_number() ? a["command_code"].get<int>() : 0;
      a["command"] = kind > 0 ? nlohmann::json(plcopen::command_kind_name(static_cast<plcopen::CommandKind>(kind - 1)))
                              : nlohmann::json(nullptr);
      const std::int64_t source = a["command_block_index"].is_number() ? a["command_block_index"].get<std::int64_t>() : -1;
      a["command_block"] = source >= 0 && static_cast<std::size_t>(source) < t->blocks.size()
                               ? nlohmann::json(t->blocks[static_cast<std::size_t>(source)].name)
                               : nlohmann::json(nullptr);
      const auto error =
          static_cast<plcopen::AxisError>(a["error_id"].is_number() ? a["error_id"].get<std::uint16_t>() : 0);
      a["error"] = plcopen::axis_error_text(error);
      a["hmi_enable_wired"] = pin_wired(b, plcopen::kAxHmiEnable);
      axes->push_back(std::move(a));
    }
  }
  return true;
}

// The axis's state now (its `state` pin), nullopt while its monitoring starts.
std::optional<AxisState> state_now(Program& p, const BlockInstance& b) {
  auto r = p.resolve(b.name + ".state");
  if (!r) return std::nullopt;
  Cell c;
  if (!p.read_value(*r, &c)) return std::nullopt;
  return static_cast<AxisState>(c.get<std::int16_t>());
}

// A command on one axis: `pin` written with `value` at the next scan of its
// task. `check` may refuse it (answered, false) with the axis's state.
template <class Check>
void axis_command(ApiContext& c, const http::Request& req, http::Response& res, Role role, int pin, bool value,
                  const char* what, Check check) {
  auto who = c.need(req, res, role);
  if (!who) return;
  // As every write: a JSON body (an empty object will do), which another
  // site's form cannot send.
  if (!c.json_body(req, res)) return;
  const std::string name = req.matches[1];
  std::string task, event;
  const bool read = c.with_published_program([&](Program& p) {
    const AxisAt at = find_axis(p, name);
    if (!at.block) {
      send_error(res, 404, "no axis '" + name + "' (an instance of MC_AXIS)");
      return true;
    }
    task = at.task->config().name;
    if (at.task->stopped()) {
      send_error(res, 409, "task " + task + " has stopped: its axes take no command until it runs again");
      return true;
    }
    if (pin_wired(*at.block, pin)) {
      send_error(res, 409, name + "." + at.block->type->pins[static_cast<std::size_t>(pin)].name +
                               " is wired in the project: the program decides it, not the HMI");
      return true;
    }
    const auto state = state_now(p, *at.block);
    if (!state) return false;
    if (!check(*state, res)) return true;
    QueuedWrite w;
    w.cell = at.block->pin_cell[static_cast<std::size_t>(pin)];
    w.value.set<bool>(value);
    if (!at.task->enqueue(&w, 1)) {
      send_error(res, 409, "task " + task + "'s write queue is full; try again");
      return true;
    }
    event = name + ": " + what;
    send_json(res, 200, {{"ok", true}, {"axis", name}, {"command", what}, {"task", task},
                         {"state", plcopen::axis_state_name(*state)}});
    return true;
  });
  if (!read) send_error(res, 503, "axis " + name + "'s state could not be read; try again");
  if (!event.empty()) c.host.record_event("hmi-write", task, event + " (by " + who->user + ")", ApiContext::client(req));
}

}  // namespace

void add_axis_routes(http::Router& s, ApiContext& c) {
  s.Get("/api/v1/axes", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const bool all = sees_everything(c.session(req));
    nlohmann::json axes;
    std::int64_t now = -1;
    c.with_published_program([&](Program& p) {
      const auto hidden = all ? nullptr : c.hidden_cells.get(p, c.host.program_generation());
      const bool complete = read_axes(p, c.host.program_generation(), hidden.get(), &axes);
      now = logical_now_ns(p);
      return complete;
    });
    send_json(res, 200, {{"now_ns", now}, {"axes", axes}});
  });

  s.Post(R"(/api/v1/axes/([^/]+)/reset)", [&c](const http::Request& req, http::Response& res) {
    axis_command(c, req, res, Role::Engineer, plcopen::kAxHmiReset, true, "reset",
                 [&](AxisState state, http::Response& r) {
                   if (state == AxisState::ErrorStop) return true;
                   send_error(r, 409, std::string(req.matches[1]) + " is in " + plcopen::axis_state_name(state) +
                                          ", not ErrorStop: there is no axis error to reset");
                   return false;
                 });
  });
  s.Post(R"(/api/v1/axes/([^/]+)/enable)", [&c](const http::Request& req, http::Response& res) {
    axis_command(c, req, res, Role::Operator, plcopen::kAxHmiEnable, true, "enable",
                 [](AxisState, http::Response&) { return true; });
  });
  s.Post(R"(/api/v1/axes/([^/]+)/disable)", [&c](const http::Request& req, http::Response& res) {
    axis_command(c, req, res, Role::Operator, plcopen::kAxHmiEnable, false, "disable",
                 [](AxisState, http::Response&) { return true; });
  });
}

}  // namespace syncplc::web
