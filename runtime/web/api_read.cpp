// The reads (docs/http-api.md, "Reading"): status, tags, values, blocks,
// forces from the running program; events, trends and project versions
// from the PLC's database on a read-only connection of the request's own.
#include <algorithm>
#include <charconv>
#include <limits>

#include "runtime/store/event_log.hpp"
#include "runtime/store/log_queries.hpp"
#include "runtime/store/project_store.hpp"
#include "runtime/web/api.hpp"
#include "runtime/web/program_json.hpp"
#include "runtime/web/read_access.hpp"

namespace syncplc::web {
namespace {

std::vector<std::string> split_refs(const std::string& text) {
  // Commas between references; a comma inside [] separates the indexes of
  // one element of a multi-dimensional array ("cell.grid[1, 2]").
  std::vector<std::string> out;
  std::string r;
  int depth = 0;
  for (char c : text) {
    if (c == ',' && depth == 0) {
      if (!r.empty()) out.push_back(std::move(r));
      r.clear();
      continue;
    }
    depth += c == '[' ? 1 : c == ']' && depth > 0 ? -1 : 0;
    r.push_back(c);
  }
  if (!r.empty()) out.push_back(std::move(r));
  return out;
}

// An integer query parameter; `fallback` when absent; 400 answered when malformed.
std::optional<std::int64_t> int_param(const http::Request& req, http::Response& res, const char* name,
                                      std::int64_t fallback) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.get_param_value(name);
  std::int64_t out = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || end != v.data() + v.size()) {
    send_error(res, 400, std::string("query parameter ") + name + "='" + v + "' is not an integer");
    return std::nullopt;
  }
  return out;
}

// The PLC's database, read-only, for one request; 503 answered when there is none.
std::unique_ptr<store::Database> read_database(ApiContext& c, http::Response& res) {
  const std::string path = c.host.database_path();
  if (path.empty() || path == store::kMemoryDatabase) {
    send_error(res, 404, "this PLC keeps no database (--db :memory:): no events, trends or project versions");
    return nullptr;
  }
  std::string error;
  auto db = store::Database::open_read_only(path, &error);
  if (!db) send_error(res, 503, error);
  return db;
}

// A version's error lines for a reader who may not see paths.
nlohmann::json hidden_dirs(const std::vector<std::string>& lines) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& l : lines) out.push_back(without_dirs(l));
  return out;
}

}  // namespace

void add_read_routes(http::Router& s, ApiContext& c) {
  s.Get("/api/v1/status", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    nlohmann::json runtime = c.host.runtime_status();
    const nlohmann::json states = runtime.value("task_states", nlohmann::json::object());
    runtime.erase("task_states");
    if (!sees_everything(c.session(req))) hide_paths(runtime);  // read_access.hpp
    const std::string histograms = req.get_param_value("histograms");
    if (!histograms.empty() && histograms != "full") {
      send_error(res, 400, "histograms='" + histograms + "': the only choice is histograms=full");
      return;
    }
    nlohmann::json j{{"runtime", runtime}};
    c.host.with_program([&](Program& p) {
      j["runtime"]["program"] = p.name;
      j["runtime"]["program_version"] = p.version;
      nlohmann::json tasks = nlohmann::json::array();
      for (const auto& t : p.tasks)
        tasks.push_back(task_json(*t, states.value(t->config().name, nlohmann::json()), !histograms.empty()));
      j["tasks"] = tasks;
      j["forces"] = p.force_count();
    });
    send_json(res, 200, j);
  });

  s.Get("/api/v1/tags", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const std::string filter = req.get_param_value("filter");
    const bool all = sees_everything(c.session(req));
    nlohmann::json tags = nlohmann::json::array();
    c.host.with_program([&](Program& p) {
      const ForcedCells forced = forced_cells(p);
      for (const auto& t : p.tags)
        if ((all || t.hmi != HmiAccess::None) && (filter.empty() || t.name.find(filter) != std::string::npos))
          tags.push_back(tag_json(p, t, forced));
    });
    send_json(res, 200, {{"tags", tags}});
  });

  s.Get(R"(/api/v1/tags/([^/]+))", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const std::string name = req.matches[1];
    const bool all = sees_everything(c.session(req));
    c.host.with_program([&](Program& p) {
      const Tag* t = p.find_tag(name);
      if (!t) send_error(res, 404, "no tag '" + name + "'");
      else if (!all && t->hmi == HmiAccess::None) send_error(res, 403, hidden_reason(name));
      else send_json(res, 200, tag_json(p, *t, forced_cells(p)));
    });
  });

  s.Get("/api/v1/values", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const auto refs = split_refs(req.get_param_value("refs"));
    if (refs.empty()) {
      send_error(res, 400, "name the values to read: /api/v1/values?refs=tag,tag[2],instance.pin");
      return;
    }
    nlohmann::json values = nlohmann::json::object(), forced = nlohmann::json::object();
    const bool all = sees_everything(c.session(req));
    bool ok = true;
    // A pin nobody watched is asked again a little later rather than
    // answered null (ApiContext::with_published_program).
    c.with_published_program([&](Program& p) {
      bool starting = false;
      const ForcedCells fc = forced_cells(p);
      const auto hidden = all ? nullptr : c.hidden_cells.get(p, c.host.program_generation());
      for (const auto& ref : refs) {
        std::string why;
        auto r = p.resolve(ref, &why);
        if (!r) {
          send_error(res, 404, why.empty() ? "no tag or pin '" + ref + "'" : why);
          ok = false;
          return true;
        }
        if (hidden && hidden->hides(*r)) {
          send_error(res, 403, hidden_reason(ref));
          ok = false;
          return true;
        }
        const RefValue v = ref_value(p, *r, fc);
        starting = starting || v.value.is_null();
        values[ref] = v.value;
        forced[ref] = v.forced;
      }
      return !starting;
    });
    if (ok) send_json(res, 200, {{"t_ns", store::wall_now_ns()}, {"values", values}, {"forced", forced}});
  });

  s.Get("/api/v1/blocks", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    nlohmann::json blocks = nlohmann::json::array();
    const bool all = sees_everything(c.session(req));
    c.host.with_program([&](Program& p) {
      const ForcedCells fc = forced_cells(p);
      const auto hidden = all ? nullptr : c.hidden_cells.get(p, c.host.program_generation());
      for (const auto& b : p.block_instances()) {
        blocks.push_back(instance_json(p, b, fc));
        if (hidden) hide_pins(blocks.back(), b, *hidden);
      }
    });
    send_json(res, 200, {{"blocks", blocks}});
  });

  s.Get(R"(/api/v1/blocks/([^/]+))", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const std::string name = req.matches[1];
    const bool all = sees_everything(c.session(req));
    c.host.with_program([&](Program& p) {
      for (const auto& b : p.block_instances())
        if (b.name == name) {
          nlohmann::json j = instance_json(p, b, forced_cells(p));
          if (!all) hide_pins(j, b, *c.hidden_cells.get(p, c.host.program_generation()));
          send_json(res, 200, j);
          return;
        }
      send_error(res, 404, "no block instance '" + name + "'");
    });
  });

  s.Get("/api/v1/forces", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    nlohmann::json list = nlohmann::json::array();
    const bool all = sees_everything(c.session(req));
    c.host.with_program([&](Program& p) {
      const auto hidden = all ? nullptr : c.hidden_cells.get(p, c.host.program_generation());
      for (const auto& f : p.forces())
        list.push_back({{"ref", f.ref},
                        {"value", hidden && hidden->hides(f.cell) ? nlohmann::json() : nlohmann::json(f.value_text)},
                        {"task", f.task}});
    });
    send_json(res, 200, {{"forces", list}});
  });

  s.Get("/api/v1/events", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    auto since = int_param(req, res, "since", 0);
    if (!since) return;
    auto limit = int_param(req, res, "limit", 200);
    if (!limit) return;
    if (*limit < 1 || *limit > 10000) {
      send_error(res, 400, "limit must be 1..10000");
      return;
    }
    auto db = read_database(c, res);
    if (!db) return;
    store::EventFilter f;
    f.after_id = *since;
    f.limit = *limit;
    // Without `since`: the newest; with it, the next ones after it, so a
    // reader that follows (since = the last id it has) misses none.
    f.newest = *since == 0;
    if (req.has_param("kind") && !req.get_param_value("kind").empty()) f.kinds = split_refs(req.get_param_value("kind"));
    nlohmann::json events = nlohmann::json::array();
    const bool all = sees_everything(c.session(req));
    if (!db->sql().tableExists("events")) {
      send_json(res, 200, {{"events", events}});  // no event recorded yet
      return;
    }
    for (const auto& e : store::read_events(*db, f))
      events.push_back({{"id", e.id},
                        {"time_ns", e.time_ns},
                        {"kind", e.kind},
                        {"task", e.task},
                        {"source", all ? e.source : without_dirs(e.source)},
                        {"message", all ? e.message : without_dirs(e.message)},
                        {"client", e.client},
                        {"scan", e.scan ? nlohmann::json(*e.scan) : nlohmann::json()}});
    send_json(res, 200, {{"events", events}});
  });

  s.Get("/api/v1/trends", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    const std::string tag = req.get_param_value("tag");
    if (tag.empty()) {
      send_error(res, 400, "name the trended tag: /api/v1/trends?tag=speed");
      return;
    }
    auto since = int_param(req, res, "since", std::numeric_limits<std::int64_t>::min());
    if (!since) return;
    auto until = int_param(req, res, "until", std::numeric_limits<std::int64_t>::max());
    if (!until) return;
    auto points = int_param(req, res, "points", 500);
    if (!points) return;
    if (!sees_everything(c.session(req))) {
      bool hidden = false;
      c.host.with_program([&](Program& p) {
        if (auto r = p.resolve(tag)) hidden = c.hidden_cells.get(p, c.host.program_generation())->hides(*r);
      });
      if (hidden) {
        send_error(res, 403, hidden_reason(tag));
        return;
      }
    }
    if (*points < 1 || *points > 10000) {
      send_error(res, 400, "points must be 1..10000");
      return;
    }
    auto db = read_database(c, res);
    if (!db) return;
    std::string why;
    auto series = store::find_trend_series(*db, {tag}, &why);
    if (series.empty()) {
      send_error(res, 404, why);
      return;
    }
    nlohmann::json out = nlohmann::json::array();
    for (const auto& one : series) {
      // At most `points`: consecutive buckets merged evenly (min of mins,
      // max of maxes, mean weighted by the scans in each), folded as the
      // rows come, never all of them in memory.
      const std::int64_t n = store::count_trend_rows(*db, {one}, *since, *until);
      const std::int64_t step = std::max<std::int64_t>(1, (n + *points - 1) / *points);
      nlohmann::json pts = nlohmann::json::array();
      store::TrendRow m;
      double weighted = 0;
      std::int64_t in_point = 0;
      auto flush = [&] {
        if (in_point == 0) return;
        if (m.count > 0) m.mean = weighted / static_cast<double>(m.count);
        pts.push_back({{"t_ns", m.t_ns}, {"min", m.min}, {"max", m.max}, {"mean", m.mean}, {"count", m.count}});
        in_point = 0;
      };
      store::for_each_trend_row(*db, {one}, *since, *until, [&](const store::TrendRow& r) {
        if (in_point == 0) {
          m = r;
          weighted = r.mean * static_cast<double>(r.count);
        } else {
          m.min = std::min(m.min, r.min);
          m.max = std::max(m.max, r.max);
          weighted += r.mean * static_cast<double>(r.count);
          m.count += r.count;
        }
        if (++in_point == step) flush();
      });
      flush();
      out.push_back({{"label", one.label}, {"unit", one.unit}, {"points", pts}});
    }
    if (out.size() == 1) send_json(res, 200, {{"tag", tag}, {"unit", out[0]["unit"]}, {"points", out[0]["points"]}});
    else send_json(res, 200, {{"tag", tag}, {"series", out}});
  });

  s.Get("/api/v1/projects", [&c](const http::Request& req, http::Response& res) {
    if (!c.may_read(req, res)) return;
    auto db = read_database(c, res);
    if (!db) return;
    const std::string running_hash = c.host.runtime_status().value("project_hash", "");
    const bool all = sees_everything(c.session(req));
    nlohmann::json versions = nlohmann::json::array();
    if (db->sql().tableExists("project_versions")) {
      for (const auto& v : store::list_versions(db->sql()))
        versions.push_back({{"version", v.number},
                            {"time_ns", v.time_ns},
                            {"origin", v.origin},
                            {"source", all ? v.source : without_dirs(v.source)},
                            {"outcome", v.accepted ? "accepted" : "rejected"},
                            {"project", v.project_name + (v.project_version.empty() ? "" : " " + v.project_version)},
                            {"hash", v.hash},
                            {"files", v.files},
                            {"errors", all ? nlohmann::json(v.errors) : hidden_dirs(v.errors)},
                            {"running", false}});
      // The newest accepted version whose files are the running program's.
      for (auto it = versions.rbegin(); it != versions.rend(); ++it)
        if ((*it)["outcome"] == "accepted" && (*it)["hash"] == running_hash) {
          (*it)["running"] = true;
          break;
        }
    }
    send_json(res, 200, {{"versions", versions}});
  });
}

}  // namespace syncplc::web
