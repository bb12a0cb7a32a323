// Writes and forces (docs/http-api.md, "Changing the PLC"): through the
// owning task's write queue, as Modbus writes go; every one an event naming
// the user and the client.
#include <type_traits>
#include <vector>

#include "runtime/core/tag_limits.hpp"
#include "runtime/core/units.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/json_values.hpp"

namespace syncplc::web {
namespace {

// "tag" or "tag[i]" (i within the declared bounds) → the tag and the first
// element and count to write; 404/400 answered otherwise.
struct WriteTarget {
  const Tag* tag = nullptr;
  std::uint32_t element = 0;
  bool whole = true;
};

std::optional<WriteTarget> write_target(const Program& p, const std::string& name, http::Response& res) {
  WriteTarget w;
  std::string base = name;
  std::int64_t index = 0;
  const auto open = name.find('[');
  if (open != std::string::npos) {
    if (name.back() != ']') {
      send_error(res, 400, "'" + name + "': write an element as tag[i]");
      return std::nullopt;
    }
    base = name.substr(0, open);
    const std::string digits = name.substr(open + 1, name.size() - open - 2);
    try {
      std::size_t used = 0;
      index = std::stoll(digits, &used);
      if (used != digits.size()) throw std::invalid_argument(digits);
    } catch (const std::exception&) {
      send_error(res, 400, "'" + name + "': the index must be an integer");
      return std::nullopt;
    }
    w.whole = false;
  }
  w.tag = p.find_tag(base);
  if (!w.tag) {
    send_error(res, 404, "no tag '" + base + "'");
    return std::nullopt;
  }
  if (!w.whole) {
    const bool array = w.tag->is_array || w.tag->length > 1;
    const std::int64_t first = w.tag->array_lower, last = first + w.tag->length - 1;
    if (!array || index < first || index > last) {
      send_error(res, 404, array ? "'" + name + "': the index is outside " + base + "'s bounds " + std::to_string(first) +
                                       ".." + std::to_string(last)
                                 : "'" + base + "' is not an array");
      return std::nullopt;
    }
    w.element = static_cast<std::uint32_t>(index - first);
  }
  return w;
}

// The cells a written JSON value gives: one element, or every element of
// an array from a JSON array of its length. 400 answered otherwise.
std::optional<std::vector<Cell>> written_cells(const Tag& t, bool whole, const nlohmann::json& v, http::Response& res) {
  const bool array = t.is_array || t.length > 1;
  std::vector<nlohmann::json> items;
  if (whole && array) {
    if (!v.is_array() || v.size() != t.length) {
      send_error(res, 400, t.name + " has " + std::to_string(t.length) + " elements: send an array of " +
                               std::to_string(t.length) + " values, or write one element as " + t.name + "[i]");
      return std::nullopt;
    }
    items.assign(v.begin(), v.end());
  } else {
    items.push_back(v);
  }
  std::vector<Cell> cells;
  for (const auto& item : items) {
    std::string why;
    auto text = value_text(item, &why);
    std::optional<Cell> cell;
    if (text) cell = parse_value_in_unit(t.type, t.unit, *text, &why);
    if (!cell) {
      send_error(res, 400, t.name + ": " + why);
      return std::nullopt;
    }
    // The project's engineering limits (tag_limits.hpp): the HMI's
    // setpoints come this way too.
    if (std::string outside = outside_limits(t, *cell); !outside.empty()) {
      send_error(res, 400, t.name + ": " + outside + "; nothing was written");
      return std::nullopt;
    }
    cells.push_back(*cell);
  }
  return cells;
}

nlohmann::json force_json(const ForceResult& r) {
  return {{"ok", true}, {"ref", r.ref}, {"value", r.value}, {"previous", r.previous}, {"task", r.task}};
}

// A refused force or unforce: a reference that names nothing (404), a
// value that does not parse (400), or the PLC's state (409: max_forces, a
// stopped task, a full queue, an online change under way).
int force_status(const Program& p, const std::string& ref, const ForceResult& r) {
  if (!p.resolve(ref)) return 404;
  if (r.error.rfind("value '", 0) == 0) return 400;
  if (r.unforce && r.error == r.ref + " is not forced") return 404;
  if (r.error.find("is an array of") != std::string::npos) return 400;
  return 409;
}

// A variable of an ST instance (instance.path, not a pin; Program::
// resolve_variable): an engineer's one-shot write, as CODESYS's "write
// value": queued for the start of its task's next scan, from where the
// program goes on (its next assignment replaces it; to hold a value, force
// it). Operators write tags with hmi: readwrite only. False when `name` is
// no such variable (a tag or a pin: the caller goes on); otherwise answered.
bool variable_write(const Program& p, const std::string& name, const Session& who, const nlohmann::json& value,
                    http::Response& res, std::string* event, std::string* task) {
  bool names_one = false;
  std::string why;
  BlockTypeInfo::Variable info;
  const auto r = p.resolve_variable(name, &names_one, &why, &info);
  if (!names_one) return false;
  if (!r) {
    send_error(res, 404, why);
    return true;
  }
  if (!info.read_only.empty()) {
    send_error(res, 409, name + " cannot be written: " + info.read_only);
    return true;
  }
  if (who.role < Role::Engineer) {
    send_error(res, 403, name + " is a variable of an ST instance: writing it needs the engineer role (operators "
                               "write tags with hmi: readwrite)");
    return true;
  }
  *task = p.tasks[r->task]->config().name;
  if (p.tasks[r->task]->stopped()) {
    send_error(res, 409, "task " + *task + " has stopped: nothing it owns can be written until it runs again");
    return true;
  }
  auto text = value_text(value, &why);
  std::optional<Cell> cell;
  if (text) cell = parse_value(r->type, *text, &why);
  if (!cell) {
    send_error(res, 400, name + ": " + why);
    return true;
  }
  if (info.range) {  // a subrange: what an assignment in ST would keep it in
    // Subranges are of integer types; the value as the ST checker compares it (64-bit signed).
    const std::int64_t x = dispatch_type(r->type, [&]<IecType T>() -> std::int64_t {
      using N = typename Native<T>::type;
      if constexpr (std::is_integral_v<N>) return static_cast<std::int64_t>(cell->get<N>());
      else return 0;
    });
    if (x < info.range->first || x > info.range->second) {
      send_error(res, 400, name + ": " + std::to_string(x) + " is outside its subrange " +
                               std::to_string(info.range->first) + ".." + std::to_string(info.range->second));
      return true;
    }
  }
  const QueuedWrite w{r->cell, *cell};
  if (!p.tasks[r->task]->enqueue(&w, 1)) {
    send_error(res, 409, "task " + *task + "'s write queue is full; try again");
    return true;
  }
  const std::string shown = format_value(r->type, *cell);
  *event = name + " := " + shown;
  send_json(res, 200, {{"ok", true}, {"tag", name}, {"value", shown}, {"task", *task}});
  return true;
}

}  // namespace

void add_change_routes(http::Router& s, ApiContext& c) {
  s.Put(R"(/api/v1/tags/([^/]+))", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Operator);
    if (!who) return;
    auto body = c.json_body(req, res);
    if (!body) return;
    if (!body->contains("value")) {
      send_error(res, 400, R"(expected {"value": ...})");
      return;
    }
    const std::string name = req.matches[1];
    std::string event, task;
    c.host.with_program([&](Program& p) {
      if (variable_write(p, name, *who, (*body)["value"], res, &event, &task)) return;
      auto w = write_target(p, name, res);
      if (!w) return;
      const Tag& t = *w->tag;
      // An hmi: none tag is not shown outside the PLC (read_access.hpp):
      // nothing about it, not even who writes it.
      if (t.hmi == HmiAccess::None) {
        send_error(res, 403, t.name + " cannot be written from outside (hmi: none)");
        return;
      }
      // Then the program's own tag: that, not the role or the hmi: key, is
      // why a write cannot hold (a tag a block or driver writes can never
      // be hmi: readwrite).
      if (!t.writer.empty()) {
        send_error(res, 409, t.name + " is written by the program (" + t.writer + (t.written_every_scan ? " every scan" : "") +
                                 "): a write would be overwritten at once; an engineer can force it instead "
                                 "(syncplc force " + t.name + " VALUE)");
        return;
      }
      if (t.hmi != HmiAccess::ReadWrite) {
        send_error(res, 403, t.name + " cannot be written from outside (hmi: " + std::string(hmi_access_name(t.hmi)) +
                                 "; the project gives it hmi: readwrite to allow it)");
        return;
      }
      task = p.tasks[t.owner]->config().name;
      if (p.tasks[t.owner]->stopped()) {
        send_error(res, 409, "task " + task + " has stopped: nothing it owns can be written until it runs again");
        return;
      }
      auto cells = written_cells(t, w->whole, (*body)["value"], res);
      if (!cells) return;
      if (!p.write_tag(t, w->element, cells->data(), static_cast<std::uint32_t>(cells->size()))) {
        send_error(res, 409, "task " + task + "'s write queue is full; try again");
        return;
      }
      std::string shown;
      for (std::size_t i = 0; i < cells->size(); ++i) shown += (i ? ", " : "") + format_value(t.type, (*cells)[i]);
      if (cells->size() > 1) shown = "[" + shown + "]";
      event = name + " := " + shown + (t.unit.empty() ? "" : " " + t.unit);
      send_json(res, 200, {{"ok", true}, {"tag", name}, {"value", shown}, {"task", task}});
    });
    if (!event.empty()) c.host.record_event("hmi-write", task, event + " (by " + who->user + ")", ApiContext::client(req));
  });

  s.Post("/api/v1/forces", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Engineer);
    if (!who) return;
    auto body = c.json_body(req, res);
    if (!body) return;
    const auto ref = body->find("ref");
    if (ref == body->end() || !ref->is_string() || !body->contains("value")) {
      send_error(res, 400, R"(expected {"ref": "tag or instance.pin", "value": ...})");
      return;
    }
    std::string why;
    auto text = value_text((*body)["value"], &why);
    if (!text) {
      send_error(res, 400, why);
      return;
    }
    ForceResult r;
    int status = 200;
    c.host.with_program([&](Program& p) {
      r = p.force(ref->get<std::string>(), *text);
      if (!r.ok) status = force_status(p, ref->get<std::string>(), r);
    });
    if (!r.ok) {
      send_error(res, status, r.error);
      return;
    }
    c.host.record_event("force", r.task, r.event_text() + " (by " + who->user + ")", ApiContext::client(req));
    send_json(res, 200, force_json(r));
  });

  s.Delete(R"(/api/v1/forces/(.+))", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Engineer);
    if (!who) return;
    const std::string ref = req.matches[1];
    ForceResult r;
    int status = 200;
    c.host.with_program([&](Program& p) {
      r = p.unforce(ref);
      if (!r.ok) status = force_status(p, ref, r);
    });
    if (!r.ok) {
      send_error(res, status, r.error);
      return;
    }
    c.host.record_event("unforce", r.task, r.event_text() + " (by " + who->user + ")", ApiContext::client(req));
    send_json(res, 200, force_json(r));
  });

  s.Delete("/api/v1/forces", [&c](const http::Request& req, http::Response& res) {
    auto who = c.need(req, res, Role::Engineer);
    if (!who) return;
    std::vector<ForceResult> released;
    c.host.with_program([&](Program& p) { released = p.unforce_all(); });
    nlohmann::json refs = nlohmann::json::array();
    for (const auto& r : released) {
      if (!r.ok) {
        send_error(res, 409, r.error);
        return;
      }
      refs.push_back(r.ref);
      c.host.record_event("unforce", r.task, r.event_text() + " (by " + who->user + ")", ApiContext::client(req));
    }
    send_json(res, 200, {{"ok", true}, {"released", refs}});
  });
}

}  // namespace syncplc::web
