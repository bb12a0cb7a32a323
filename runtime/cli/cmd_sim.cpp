#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>

#include "runtime/cli/commands.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/io/dds/virtual_bus.hpp"
#include "runtime/project/system.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/report.hpp"
#include "runtime/project/trace_csv.hpp"

namespace syncplc::cli {

int cmd_sim(const std::string& project, const std::string& duration, std::optional<std::uint64_t> seed,
            const std::string& trace, const std::vector<std::string>& sets, bool quiet, const std::string& metrics_path) {
  std::string err;
  auto d = parse_duration_ns(duration, &err);
  if (!d || *d <= 0) {
    std::cerr << "syncplc: --duration: " << (d ? "must be positive" : err) << "\n";
    return kExitInvalid;
  }
  LoadOptions o;
  o.seed = seed;
  if (!parse_sets(sets, o)) return kExitInvalid;
  if (is_system_file(project)) return cmd_sim_system(project, *d, o, trace, quiet, metrics_path);
  // Virtual time: a dds driver's subscriptions see what this project
  // publishes itself (a system file runs all the nodes together).
  o.virtual_time = true;
  o.bus = std::make_shared<VirtualBus>();
  auto r = load_or_report(project, o);
  if (!r.ok()) return kExitInvalid;
  Program& p = *r.program;

  std::ofstream out;
  if (!trace.empty()) {
    out.open(trace, std::ios::binary | std::ios::trunc);
    if (!out) {
      std::cerr << "syncplc: cannot write trace file " << trace << "\n";
      return kExitInvalid;
    }
    if (p.traces.empty()) std::cerr << "syncplc: warning: the project has no traces: the CSV has only time_s\n";
    write_trace_header(out, p);
  }
  if (!p.open_drivers(&err)) {
    std::cerr << "syncplc: " << err << "\n";
    return kExitInvalid;
  }
  for (const auto& w : o.bus->unmatched())
    std::cerr << "syncplc: warning: " << w << " (simulated on its own; run the system file to simulate every node)\n";
  std::ofstream metrics_out;
  if (!metrics_path.empty()) {
    metrics_out.open(metrics_path, std::ios::binary | std::ios::trunc);
    if (!metrics_out) {
      std::cerr << "syncplc: cannot write metrics file " << metrics_path << "\n";
      return kExitInvalid;
    }
    if (r.metrics.axis_errors.empty())
      std::cerr << "syncplc: warning: the project names no metrics axis_errors: the metrics hold statistics only\n";
  }
  VirtualClock clock(p);
  MotionMetrics metrics(r.metrics);
  clock.on_time_point([&](std::int64_t t) {
    if (out.is_open()) write_trace_row(out, p, clock.image_access(), t);
    if (metrics.enabled()) metrics.sample(p, clock.image_access(), t, clock.scans(metrics.task()));
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
  p.stop_drivers();  // the end of the run is a clean stop: the drivers' at_stop
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  print_events(std::cerr, p);
  std::cout << fmt::format("Simulated {} of {} in {:.3f}s wall time (seed {})\n", format_duration(*d), p.name, wall, p.seed);
  print_statistics(std::cout, p, true);
  if (out.is_open()) {
    out.flush();
    if (!out) {
      std::cerr << "syncplc: error writing " << trace << "\n";
      return kExitInvalid;
    }
    std::cout << "Trace: " << trace << " (" << p.traces.size() << " columns)\n";
  }
  if (metrics.enabled())
    std::cout << fmt::format("Track-RSME {:.6g}  Sync-RSME {:.6g}  ({} samples, paper 000 eqs. 26-27)\n",
                             metrics.track_rsme(), metrics.sync_rsme(), metrics.samples());
  if (const ContourMetric* c = metrics.contour())
    std::cout << fmt::format("Contour error  mean {:.6g}  max {:.6g}  RMS {:.6g}  (|distance| from the path)\n",
                             c->mean_abs(), c->max_abs(), c->rms());
  if (metrics_out.is_open()) {
    metrics_out << metrics.json(p, *d, wall);
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
