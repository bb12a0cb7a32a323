// syncplc status, read, write, force, unforce: one request each to a
// running `syncplc run` (docs/http-api.md), its answer in a few lines.
#include <fmt/format.h>

#include <cmath>
#include <iostream>

#include "runtime/cli/api_client.hpp"
#include "runtime/cli/commands.hpp"
#include "runtime/cli/live_screen.hpp"
#include "runtime/cli/online_values.hpp"
#include "runtime/cli/ref_units.hpp"

namespace syncplc::cli {
namespace {

using nlohmann::json;

std::optional<double> number(const json& j, const char* key) {
  if (j.is_object() && j.contains(key) && j[key].is_number()) return j[key].get<double>();
  return std::nullopt;
}

// An answer's field, or `fallback` (a server that answers {"ok": true} only).
json field(const json& j, const char* key, const json& fallback) {
  return j.is_object() && j.contains(key) && !j[key].is_null() ? j[key] : fallback;
}

std::string text(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return "";
  return j[key].is_string() ? j[key].get<std::string>() : j[key].dump();
}

// A task period as it is written in a project: 1ms, 250us, 2s.
std::string period_text(std::int64_t ns) {
  if (ns > 0 && ns % 1'000'000'000 == 0) return std::to_string(ns / 1'000'000'000) + "s";
  if (ns > 0 && ns % 1'000'000 == 0) return std::to_string(ns / 1'000'000) + "ms";
  if (ns > 0 && ns % 1'000 == 0) return std::to_string(ns / 1'000) + "us";
  return compact_ns(ns);
}

std::string uptime_text(double s) {
  const auto t = static_cast<std::int64_t>(s);
  if (t >= 86400) return fmt::format("{}d {}h", t / 86400, t % 86400 / 3600);
  if (t >= 3600) return fmt::format("{}h {}m", t / 3600, t % 3600 / 60);
  if (t >= 60) return fmt::format("{}m {}s", t / 60, t % 60);
  return fmt::format("{}s", t);
}

// A statistic's p99 ("exec": {"p99_ns"}), "-" when the server has none yet.
std::string p99_text(const json& task, const char* key) {
  if (!task.is_object() || !task.contains(key)) return "-";
  const auto p99 = number(task[key], "p99_ns");
  return p99 ? compact_ns(static_cast<std::int64_t>(std::llround(*p99))) : "-";
}

void print_status(const json& s, const std::string& url) {
  const json rt = field(s, "runtime", json::object());
  std::cout << "syncplc " << text(rt, "version") << " at " << url;
  if (auto up = number(rt, "uptime_s")) std::cout << ", up " << uptime_text(*up);
  std::cout << "\n";
  std::string program = text(rt, "program");
  if (!text(rt, "program_version").empty()) program += " " + text(rt, "program_version");
  if (!text(rt, "project_file").empty()) program += " (" + text(rt, "project_file") + ")";
  if (!program.empty()) std::cout << "program  " << program << "\n";
  if (rt.contains("store") && rt["store"].is_object()) {
    std::string store = text(rt["store"], "state");
    if (!text(rt["store"], "detail").empty()) store += ": " + text(rt["store"], "detail");
    std::cout << "store    " << store << "\n";
  }
  if (!text(rt, "modbus").empty()) std::cout << "modbus   " << text(rt, "modbus") << "\n";
  std::cout << fmt::format("\n{:<14} {:>7}  {:<8} {:>7} {:>9} {:>9} {:>11}\n", "task", "period", "state", "scans",
                           "overruns", "exec p99", "jitter p99");
  for (const auto& t : field(s, "tasks", json::array())) {
    const auto period = number(t, "period_ns").value_or(0);
    const auto scans = number(t, "scans").value_or(0);
    const auto overruns = number(t, "overruns").value_or(0);
    std::cout << fmt::format("{:<14} {:>7}  {:<8} {:>7} {:>9} {:>9} {:>11}\n", shorten_middle(text(t, "name"), 14),
                             period_text(static_cast<std::int64_t>(period)), text(t, "state"),
                             compact_count(static_cast<std::uint64_t>(scans)),
                             compact_count(static_cast<std::uint64_t>(overruns)), p99_text(t, "exec"),
                             p99_text(t, "jitter"));
    if (!text(t, "stop_reason").empty()) std::cout << "               " << text(t, "stop_reason") << "\n";
  }
  const auto forces = static_cast<std::int64_t>(number(s, "forces").value_or(0));
  std::cout << "\nforces   " << (forces ? std::to_string(forces) + (forces == 1 ? " element" : " elements") +
                                             " held at forced values (syncplc unforce --all releases them)"
                                       : std::string("none"))
            << "\n";
}

}  // namespace

int cmd_status(const OnlineOptions& o) {
  return run_online("status", [&] {
    auto api = connect_api(o);
    const ApiAnswer a = api->call("GET", "/status");
    if (o.json) std::cout << a.body << "\n";
    else print_status(a.json, api->url());
    return kExitOk;
  });
}

int cmd_read(const std::vector<std::string>& refs, const OnlineOptions& o) {
  return run_online("read", [&] {
    auto api = connect_api(o);
    const ApiAnswer a = api->call("GET", "/values?refs=" + refs_query(refs));
    if (o.json) {
      std::cout << a.body << "\n";
      return kExitOk;
    }
    const auto units = ref_units(*api, refs);
    const json& values = a.json.at("values");
    const json forced = field(a.json, "forced", json::object());
    for (const auto& ref : refs) {
      std::string line = ref + " = " + format_value(values.value(ref, json()));
      if (!units.at(ref).empty()) line += " " + units.at(ref);
      if (any_forced(forced.value(ref, json()))) line += " (forced)";
      std::cout << line << "\n";
    }
    return kExitOk;
  });
}

int cmd_write(const std::string& tag, const std::string& value, const OnlineOptions& o) {
  return run_online("write", [&] {
    auto api = connect_api(o);
    const json body = {{"value", value_from_command_line(value)}};
    const ApiAnswer a = api->call("PUT", "/tags/" + url_encode(tag), &body);
    // The server's own text of the value when it sends one (a quantity converted to the tag's unit).
    std::cout << tag << " := " << format_value(field(a.json, "value", body["value"]));
    if (!text(a.json, "task").empty()) std::cout << " (queued to task " << text(a.json, "task") << ")";
    std::cout << "\n";
    return kExitOk;
  });
}

int cmd_force(const std::string& ref, const std::string& value, const OnlineOptions& o) {
  return run_online("force", [&] {
    auto api = connect_api(o);
    const json body = {{"ref", ref}, {"value", value_from_command_line(value)}};
    const ApiAnswer a = api->call("POST", "/forces", &body);
    std::cout << ref << " forced to " << format_value(field(a.json, "value", body["value"]));
    // "previous": the value it was forced to before; "" when it was not forced.
    const auto previous = field(a.json, "previous", nullptr);
    if (!previous.is_null() && !(previous.is_string() && previous.get<std::string>().empty()))
      std::cout << " (was " << format_value(a.json["previous"]) << ")";
    std::cout << "\n";
    return kExitOk;
  });
}

int cmd_unforce(const std::string& ref, bool all, const OnlineOptions& o) {
  return run_online("unforce", [&] {
    if (all == !ref.empty()) throw ApiError(kExitInvalid, "name one REF, or give --all");
    auto api = connect_api(o);
    if (!all) {
      api->call("DELETE", "/forces/" + url_encode(ref));
      std::cout << ref << " released\n";
      return kExitOk;
    }
    const ApiAnswer a = api->call("DELETE", "/forces");
    const json released = field(a.json, "released", json::array());
    if (released.empty()) {
      std::cout << "nothing was forced\n";
      return kExitOk;
    }
    std::cout << "released " << released.size() << ":";
    for (const auto& r : released) std::cout << " " << format_value(r);
    std::cout << "\n";
    return kExitOk;
  });
}

}  // namespace syncplc::cli
