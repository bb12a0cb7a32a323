// `syncplc sim SYSTEM.yaml`: every node of a distributed project in one
// process, on one virtual time line (runtime/core/system_clock.hpp) and one
// simulated bus (runtime/io/dds/virtual_bus.hpp), bit for bit reproducible.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>

#include "runtime/cli/commands.hpp"
#include "runtime/core/system_clock.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/report.hpp"
#include "runtime/project/system.hpp"
#include "runtime/project/trace_csv.hpp"

namespace syncplc::cli {

int cmd_sim_system(const std::string& path, std::int64_t duration_ns, const LoadOptions& options,
                   const std::string& trace, bool quiet, const std::string& metrics_path) {
  LoadedSystem sys = load_system_or_project(path, options);
  if (!sys.ok()) {
    for (const auto& d : sys.diagnostics.sorted()) std::cerr << d.text() << "\n";
    std::cerr << "syncplc: " << sys.diagnostics.size() << " error(s); the system was not simulated\n";
    return kExitInvalid;
  }
  std::ofstream out;
  if (!trace.empty()) {
    out.open(trace, std::ios::binary | std::ios::trunc);
    if (!out) {
      std::cerr << "syncplc: cannot write trace file " << trace << "\n";
      return kExitInvalid;
    }
    // One time column, then every node's traces as node.label.
    out << "time_s";
    for (const auto& n : sys.nodes)
      for (const auto& c : n.loaded.program->traces) out << ',' << n.name << '.' << c.label;
    out << '\n';
  }
  std::string err;
  if (!open_system(sys, &err)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  std::ofstream metrics_out;
  if (!metrics_path.empty()) {
    metrics_out.open(metrics_path, std::ios::binary | std::ios::trunc);
    if (!metrics_out) {
      std::cerr << "syncplc: cannot write metrics file " << metrics_path << "\n";
      close_system(sys);
      return kExitInvalid;
    }
  }
  std::vector<std::unique_ptr<VirtualClock>> clocks;
  std::vector<std::unique_ptr<MotionMetrics>> metrics;
  std::vector<VirtualClock*> order;
  for (auto& n : sys.nodes) {
    Program& p = *n.loaded.program;
    clocks.push_back(std::make_unique<VirtualClock>(p));
    metrics.push_back(std::make_unique<MotionMetrics>(n.loaded.metrics));
    VirtualClock& c = *clocks.back();
    MotionMetrics& m = *metrics.back();
    if (m.enabled()) c.on_time_point([&p, &c, &m](std::int64_t t) { m.sample(p, c.image_access(), t, c.scans(m.task())); });
    order.push_back(&c);
  }
  SystemClock clock(order);
  if (out.is_open())
    clock.on_time_point([&](std::int64_t t) {
      out << fmt::format("{:.9f}", static_cast<double>(t) * 1e-9);
      for (std::size_t i = 0; i < sys.nodes.size(); ++i) {
        const Program& p = *sys.nodes[i].loaded.program;
        for (const auto& c : p.traces) out << ',' << format_trace_value(c.ref.type, *clocks[i]->live_cell(c.ref));
      }
      out << '\n';
    });

  const bool progress = !quiet && isatty(STDERR_FILENO);
  const auto wall0 = std::chrono::steady_clock::now();
  const std::int64_t chunk = std::max<std::int64_t>(duration_ns / 200, 1);
  for (std::int64_t t = 0; t < duration_ns;) {
    t = std::min(duration_ns, t + chunk);
    clock.run_until(t, false);
    if (progress)
      std::cerr << fmt::format("\r  {:5.1f}%  virtual {:.3f}s  ", 100.0 * static_cast<double>(t) / static_cast<double>(duration_ns),
                               static_cast<double>(t) * 1e-9);
  }
  if (progress) std::cerr << "\r" << std::string(78, ' ') << "\r";
  for (auto& n : sys.nodes) n.loaded.program->stop_drivers();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  std::cout << fmt::format("Simulated {} of system {} ({} nodes) in {:.3f}s wall time (seed {})\n",
                           format_duration(duration_ns), sys.name, sys.nodes.size(), wall,
                           sys.seed ? std::to_string(*sys.seed) : "of each node's project");
  std::string json = "{\"system\": \"" + sys.name + "\", \"nodes\": {";
  for (std::size_t i = 0; i < sys.nodes.size(); ++i) {
    Program& p = *sys.nodes[i].loaded.program;
    std::cout << "\n== node " << sys.nodes[i].name << " (" << p.name << ", seed " << p.seed << ") ==\n";
    print_events(std::cerr, p);
    print_statistics(std::cout, p, true);
    const MotionMetrics& m = *metrics[i];
    if (m.enabled())
      std::cout << fmt::format("Track-RSME {:.6g}  Sync-RSME {:.6g}  ({} samples, paper 000 eqs. 26-27)\n", m.track_rsme(),
                               m.sync_rsme(), m.samples());
    json += (i ? ", \"" : "\"") + sys.nodes[i].name + "\": " + m.json(p, duration_ns, wall);
  }
  json += "}}\n";
  close_system(sys);
  if (out.is_open()) {
    out.flush();
    if (!out) {
      std::cerr << "syncplc: error writing " << trace << "\n";
      return kExitInvalid;
    }
    std::cout << "Trace: " << trace << "\n";
  }
  if (metrics_out.is_open()) {
    metrics_out << json;
    metrics_out.flush();
    if (!metrics_out) {
      std::cerr << "syncplc: error writing " << metrics_path << "\n";
      return kExitInvalid;
    }
    std::cout << "Metrics: " << metrics_path << "\n";
  }
  return kExitOk;
}

}  // namespace syncplc::cli
