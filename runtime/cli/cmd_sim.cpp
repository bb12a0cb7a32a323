// `syncplc sim`: a project, or every node of a system file (docs/dds.md,
// "In virtual time"), in virtual time: one process, one time line
// (runtime/core/system_clock.hpp), bit for bit reproducible. A project alone
// is a system of one unnamed node: its trace columns and metrics carry no
// node prefix.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>

#include "runtime/cli/commands.hpp"
#include "runtime/core/system_clock.hpp"
#include "runtime/io/dds/virtual_bus.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/report.hpp"
#include "runtime/project/system.hpp"
#include "runtime/project/system_run.hpp"
#include "runtime/project/trace_csv.hpp"

namespace syncplc::cli {
namespace cmd_sim_impl {

bool open_output(std::ofstream& f, const std::string& path, const char* what) {
  if (path.empty()) return true;
  f.open(path, std::ios::binary | std::ios::trunc);
  if (!f) std::cerr << "syncplc: cannot write " << what << " file " << path << "\n";
  return static_cast<bool>(f);
}

bool close_output(std::ofstream& f, const std::string& path, const char* label) {
  if (!f.is_open()) return true;
  f.flush();
  if (!f) {
    std::cerr << "syncplc: error writing " << path << "\n";
    return false;
  }
  std::cout << label << ": " << path << "\n";
  return true;
}

// The node's name and a dot, for trace columns and reports of a system.
std::string prefix(const SystemNode& n) { return n.name.empty() ? std::string() : n.name + "."; }

}  // namespace cmd_sim_impl

int cmd_sim(const std::string& project, const std::string& duration, std::optional<std::uint64_t> seed,
            const std::string& trace, const std::vector<std::string>& sets, bool quiet, const std::string& metrics_path) {
  using namespace cmd_sim_impl;
  std::string err;
  auto d = parse_duration_ns(duration, &err);
  if (!d || *d <= 0) {
    std::cerr << "syncplc: --duration: " << (d ? "must be positive" : err) << "\n";
    return kExitInvalid;
  }
  LoadOptions o;
  o.seed = seed;
  if (!parse_sets(sets, o)) return kExitInvalid;
  LoadedSystem sys = load_system_or_project(project, o);
  if (!sys.ok()) {
    for (const auto& x : sys.diagnostics.sorted()) std::cerr << x.text() << "\n";
    std::cerr << project << ": " << sys.diagnostics.size() << (sys.diagnostics.size() == 1 ? " error" : " errors")
              << ", project not loaded\n";
    return kExitInvalid;
  }
  const bool alone = sys.nodes.size() == 1 && sys.nodes[0].name.empty();

  std::ofstream out, metrics_out;
  if (!open_output(out, trace, "trace")) return kExitInvalid;
  if (out.is_open()) {
    // One time column, then every node's traces (a system's as node.label).
    out << "time_s";
    for (const auto& n : sys.nodes) {
      if (n.loaded.program->traces.empty())
        std::cerr << "syncplc: warning: " << (alone ? "the project" : "node " + n.name) << " has no traces\n";
      for (const auto& c : n.loaded.program->traces) out << ',' << prefix(n) << c.label;
    }
    out << '\n';
  }
  std::vector<std::string> warnings;
  if (!open_system(sys, &err, &warnings)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  for (const auto& w : warnings)
    std::cerr << "syncplc: warning: " << w << " (simulated on its own; a system file simulates every node)\n";
  if (!open_output(metrics_out, metrics_path, "metrics")) {
    close_system(sys);
    return kExitInvalid;
  }

  SystemRun run(sys);
  for (std::size_t i = 0; i < sys.nodes.size(); ++i)
    if (metrics_out.is_open() && alone && !run.metrics(i).enabled())
      std::cerr << "syncplc: warning: the project names no metrics axis_errors: the metrics hold statistics only\n";
  SystemClock& clock = run.clock();
  if (out.is_open())
    clock.on_time_point([&](std::int64_t t) {
      out << fmt::format("{:.9f}", static_cast<double>(t) * 1e-9);
      for (std::size_t i = 0; i < sys.nodes.size(); ++i)
        for (const auto& c : sys.nodes[i].loaded.program->traces)
          out << ',' << format_trace_value(c.ref.type, *run.node_clock(i).live_cell(c.ref));
      out << '\n';
    });

  // Progress is shown only on a terminal; it never changes what is simulated.
  const bool progress = !quiet && isatty(STDERR_FILENO);
  const auto wall0 = std::chrono::steady_clock::now();
  auto last_shown = wall0;
  const std::int64_t chunk = std::max<std::int64_t>(*d / 200, 1);
  for (std::int64_t t = 0; t < *d;) {
    t = std::min(*d, t + chunk);
    clock.run_until(t, false);
    if (progress) {
      auto now = std::chrono::steady_clock::now();
      if (now - last_shown > std::chrono::milliseconds(200)) {
        last_shown = now;
        double wall = std::chrono::duration<double>(now - wall0).count();
        std::cerr << fmt::format("\r  {:5.1f}%  virtual {:.3f}s  wall {:.1f}s  ({:.0f}x real time)  ",
                                 100.0 * static_cast<double>(t) / static_cast<double>(*d), static_cast<double>(t) * 1e-9,
                                 wall, static_cast<double>(t) * 1e-9 / std::max(wall, 1e-9));
      }
    }
  }
  if (progress) std::cerr << "\r" << std::string(78, ' ') << "\r";
  for (auto& n : sys.nodes) n.loaded.program->stop_drivers();  // the end of the run is a clean stop: the drivers' at_stop
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (alone)
    std::cout << fmt::format("Simulated {} of {} in {:.3f}s wall time (seed {})\n", format_duration(*d),
                             sys.nodes[0].loaded.program->name, wall, sys.nodes[0].loaded.program->seed);
  else
    std::cout << fmt::format("Simulated {} of system {} ({} nodes) in {:.3f}s wall time (seed {})\n", format_duration(*d),
                             sys.name, sys.nodes.size(), wall, sys.seed ? std::to_string(*sys.seed) : "of each node's project");
  std::string json;
  for (std::size_t i = 0; i < sys.nodes.size(); ++i) {
    Program& p = *sys.nodes[i].loaded.program;
    if (!alone) std::cout << "\n== node " << sys.nodes[i].name << " (" << p.name << ", seed " << p.seed << ") ==\n";
    print_events(std::cerr, p);
    print_statistics(std::cout, p, true);
    const MotionMetrics& m = run.metrics(i);
    if (m.enabled())
      std::cout << fmt::format("Track-RSME {:.6g}  Sync-RSME {:.6g}  ({} samples, paper 000 eqs. 26-27)\n", m.track_rsme(),
                               m.sync_rsme(), m.samples());
    if (const ContourMetric* c = m.contour())
      std::cout << fmt::format("Contour error  mean {:.6g}  max {:.6g}  RMS {:.6g}  (|distance| from the path)\n",
                               c->mean_abs(), c->max_abs(), c->rms());
    // A project alone: its metrics object; a system: one per node.
    if (metrics_out.is_open())
      json += alone ? m.json(p, *d, wall) : (i ? ", \"" : "{\"system\": \"" + sys.name + "\", \"nodes\": {\"") +
                                                sys.nodes[i].name + "\": " + m.json(p, *d, wall);
  }
  if (metrics_out.is_open() && !alone) json += "}}\n";
  close_system(sys);
  metrics_out << json;
  if (!close_output(out, trace, "Trace") || !close_output(metrics_out, metrics_path, "Metrics")) return kExitInvalid;
  return kExitOk;
}

}  // namespace syncplc::cli
