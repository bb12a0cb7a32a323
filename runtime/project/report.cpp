#include "runtime/project/report.hpp"

#include <fmt/format.h>

#include <cmath>

namespace syncplc {

std::string format_ns(std::int64_t ns) {
  double a = static_cast<double>(ns < 0 ? -ns : ns);
  if (a < 1e3) return fmt::format("{}ns", ns);
  if (a < 1e6) return fmt::format("{:.3g}us", static_cast<double>(ns) / 1e3);
  if (a < 1e9) return fmt::format("{:.4g}ms", static_cast<double>(ns) / 1e6);
  return fmt::format("{:.4g}s", static_cast<double>(ns) / 1e9);
}

void print_task_table(std::ostream& os, const Program& p) {
  os << fmt::format("Tasks of {} {}\n", p.name, p.version);
  os << fmt::format("  {:<16} {:>9} {:>9} {:>4} {:>9} {:>5} {:<10} {:<9} {:>6} {:>7}\n", "task", "period", "phase",
                    "prio", "watchdog", "sens", "on trip", "missed", "blocks", "cells");
  for (const auto& t : p.tasks) {
    const auto& c = t->config();
    os << fmt::format("  {:<16} {:>9} {:>9} {:>4} {:>9} {:>5} {:<10} {:<9} {:>6} {:>7}\n", c.name,
                      format_duration(c.period_ns), format_duration(c.phase_ns), c.priority,
                      c.watchdog ? format_duration(c.watchdog_ns) : "-", c.watchdog ? std::to_string(c.sensitivity) : "-",
                      c.watchdog ? std::string(watchdog_action_name(c.action)) : "-", missed_cycles_name(c.missed),
                      t->blocks.size(), t->image_cells());
  }
}

void print_execution_order(std::ostream& os, const Program& p) {
  os << "Execution order\n";
  for (const auto& t : p.tasks) {
    os << fmt::format("  task {}:\n", t->config().name);
    if (t->blocks.empty()) os << "    (no blocks)\n";
    for (std::size_t i = 0; i < t->blocks.size(); ++i) {
      const auto& b = t->blocks[i];
      std::string dt = b.type->is_generic() ? "<" + std::string(type_name(b.datatype)) + ">" : "";
      os << fmt::format("    {:>3}. {:<20} {}{}{}\n", i + 1, b.name, b.type->name, dt,
                        i < t->unit_delays ? "  (unit delay: output first, input at end of scan)" : "");
    }
    for (const auto* d : t->drivers) os << fmt::format("    driver {} (latch before, write after)\n", d->name());
  }
}

void print_tag_map(std::ostream& os, const Program& p) {
  os << "Tags\n";
  os << fmt::format("  {:<20} {:<22} {:<10} {:<12} {:<9} {:<6} {:<8} {}\n", "tag", "type", "address", "task", "hmi",
                    "retain", "unit", "written by");
  for (const auto& t : p.tags) {
    std::string ty = t.is_array ? fmt::format("ARRAY[{}..{}] OF {}", t.array_lower, t.array_lower + t.length - 1,
                                              type_name(t.type))
                                : std::string(type_name(t.type));
    os << fmt::format("  {:<20} {:<22} {:<10} {:<12} {:<9} {:<6} {:<8} {}\n", t.name, ty,
                      t.address ? t.address->text() : "-", p.tasks[t.owner]->config().name, hmi_access_name(t.hmi),
                      t.retain ? "yes" : "no", t.unit.empty() ? "-" : t.unit, t.writer.empty() ? "-" : t.writer);
  }
}

void print_statistics(std::ostream& os, const Program& p, bool virtual_time) {
  os << fmt::format("Statistics ({})\n", virtual_time ? "virtual time" : "real time");
  os << fmt::format("  {:<16} {:>10} {:>8} {:>8} {:>6} {:>30} {:>30}\n", "task", "scans", "overruns", "skipped",
                    "wd", "exec min/mean/p99/max", "jitter min/mean/p99/max");
  for (const auto& t : p.tasks) {
    auto s = t->stats.summary();
    auto quad = [](const Histogram::Summary& h) {
      if (h.count == 0) return std::string("-");
      return fmt::format("{}/{}/{}/{}", format_ns(h.min), format_ns(static_cast<std::int64_t>(h.mean)),
                         format_ns(h.p99), format_ns(h.max));
    };
    os << fmt::format("  {:<16} {:>10} {:>8} {:>8} {:>6} {:>30} {:>30}{}\n", t->config().name, s.scans, s.overruns,
                      s.skipped, s.watchdog_trips, quad(s.exec), quad(s.jitter), t->stopped() ? "  STOPPED" : "");
  }
  // What crossed the tasks' edges, for the tasks where anything did: writes
  // from HMIs and tests, LET reads that fell back to the older publication
  // (snapshot_channel.hpp), events lost to a full event ring.
  auto count = [](std::uint64_t n, const char* one, const char* many) {
    return fmt::format("{} {}", n, n == 1 ? one : many);
  };
  for (const auto& t : p.tasks) {
    auto s = t->stats.summary();
    if (s.writes_applied == 0 && s.late_reads == 0 && s.events_dropped == 0) continue;
    os << fmt::format("  {}: {}, {}, {}\n", t->config().name, count(s.writes_applied, "queued write applied", "queued writes applied"),
                      count(s.late_reads, "late read", "late reads"), count(s.events_dropped, "event dropped", "events dropped"));
  }
}

void print_driver_counters(std::ostream& os, const Program& p) {
  auto number = [](double v) {
    if (v == static_cast<double>(static_cast<std::int64_t>(v)) && v < 1e15 && v > -1e15)
      return fmt::format("{}", static_cast<std::int64_t>(v));
    return std::abs(v) < 1e9 ? fmt::format("{:.1f}", v) : fmt::format("{:.4g}", v);
  };
  bool header = false;
  for (const auto& d : p.drivers) {
    const auto counters = d.driver->counters();
    if (counters.empty()) continue;
    if (!header) os << "Drivers\n";
    header = true;
    os << fmt::format("  {} ({})\n", d.driver->name(), d.type);
    std::string what, line;  // consecutive counters of one <what> share a line
    auto flush = [&] {
      if (!line.empty()) os << "    " << (what.empty() ? "" : what + ": ") << line << "\n";
      line.clear();
    };
    for (const auto& [key, value] : counters) {
      const auto dot = key.rfind('.');
      const std::string w = dot == std::string::npos ? "" : key.substr(0, dot);
      if (w != what) flush();
      what = w;
      line += (line.empty() ? "" : " ") + key.substr(dot == std::string::npos ? 0 : dot + 1) + "=" + number(value);
    }
    flush();
  }
}

std::string format_event(const Program& p, const Event& e) {
  std::string where = p.tasks[e.task]->config().name;
  if (e.block >= 0 && static_cast<std::size_t>(e.block) < p.tasks[e.task]->blocks.size())
    where += "/" + p.tasks[e.task]->blocks[static_cast<std::size_t>(e.block)].name;
  return format_event(where, e);
}

std::string format_event(const std::string& where, const Event& e) {
  return fmt::format("[{:.6f}s] {:<14} {}: {}{}", static_cast<double>(e.time_ns) * 1e-9, event_kind_name(e.kind), where,
                     e.message, event_value_text(e));
}

std::string event_value_text(const Event& e) {
  if (e.kind == EventKind::WatchdogTrip || e.kind == EventKind::ScanOverrun)
    return " (scan took " + format_ns(static_cast<std::int64_t>(e.value * 1e9)) + ")";
  if (e.kind == EventKind::ScanHung) return " (running for " + format_ns(static_cast<std::int64_t>(e.value * 1e9)) + ")";
  if (e.kind == EventKind::ScanLate) return " (started " + format_ns(static_cast<std::int64_t>(e.value * 1e9)) + " after its release)";
  return "";
}

std::size_t print_events(std::ostream& os, Program& p) {
  std::size_t n = 0;
  for (auto& t : p.tasks) {
    Event e;
    while (t->pop_event(e)) {
      os << format_event(p, e) << "\n";
      ++n;
    }
  }
  return n;
}

}  // namespace syncplc
