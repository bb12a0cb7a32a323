// syncplc design-compensator: Ling & Lemmon's optimal dropout compensator for
// a loop (fblocks/motion/dropout_design.hpp), with the output power of zero
// fill, hold and any taps given, for OPTIMAL_COMPENSATOR's design 1. The loop
// file (docs/motion/dropout-compensators.md, "Designing one"):
//   plant: {num: [0, 0, 0.30554, ...], den: [1, -0.70669, ...]}   # P(z), powers of z^-1
//   controller: {num: [1], den: [1]}                              # optional, unit gain
//   delay: 1                                                      # frames, >= 1
//   input_variance: 1                                             # optional
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "fblocks/motion/dropout_design.hpp"
#include "runtime/cli/commands.hpp"
#include "runtime/project/yaml_tree.hpp"

namespace syncplc::cli {
namespace cmd_design_impl {

bool number(const ConfigNode& n, const std::string& what, double& out, Diagnostics& diags) {
  if (!n.is_scalar() || n.scalar.empty()) {
    diags.error(n.loc, what + " is a number");
    return false;
  }
  char* end = nullptr;
  const double v = std::strtod(n.scalar.c_str(), &end);
  if (end != n.scalar.c_str() + n.scalar.size() || !std::isfinite(v)) {
    diags.error(n.loc, what + ": '" + n.scalar + "' is not a finite number");
    return false;
  }
  out = v;
  return true;
}

bool coefficients(const ConfigNode* n, const std::string& what, std::vector<double>& out, Diagnostics& diags) {
  if (!n || !n->is_list() || n->items.empty()) {
    diags.error(n ? n->loc : SourceLoc{}, what + " is a list of coefficients in powers of z^-1, e.g. [1, -0.5]");
    return false;
  }
  out.clear();
  for (const auto& i : n->items) {
    double v = 0;
    if (!number(i, what, v, diags)) return false;
    out.push_back(v);
  }
  return true;
}

bool transfer_function(const ConfigNode& n, const std::string& what, motion::TransferFunction& tf, Diagnostics& diags) {
  if (!n.is_map()) {
    diags.error(n.loc, what + " is a map {num: [...], den: [...]}");
    return false;
  }
  for (const auto& [k, v] : n.map)
    if (k != "num" && k != "den") diags.error(v.loc, "unknown key '" + k + "' in " + what + " (num, den)");
  return coefficients(n.find("num"), what + ".num", tf.num, diags) &&
         coefficients(n.find("den"), what + ".den", tf.den, diags) && diags.empty();
}

bool read_loop(const std::string& path, motion::DropoutLoop& loop, Diagnostics& diags) {
  const ConfigNode root = read_yaml_file(path, diags);
  if (!diags.empty()) return false;
  if (!root.is_map()) {
    diags.error(root.loc, "a loop file is a map: plant, controller, delay, input_variance");
    return false;
  }
  for (const auto& [k, v] : root.map)
    if (k != "plant" && k != "controller" && k != "delay" && k != "input_variance")
      diags.error(v.loc, "unknown key '" + k + "' (plant, controller, delay, input_variance)");
  const ConfigNode* plant = root.find("plant");
  if (!plant) diags.error(root.loc, "plant: missing");
  else transfer_function(*plant, "plant", loop.plant, diags);
  if (const ConfigNode* c = root.find("controller")) transfer_function(*c, "controller", loop.controller, diags);
  if (const ConfigNode* d = root.find("delay")) {
    double v = 0;
    if (number(*d, "delay", v, diags)) {
      if (v != std::floor(v) || v < 1 || v > motion::kDropoutLoopMaxStates)
        diags.error(d->loc, "delay is a whole number of frames, 1.." + std::to_string(motion::kDropoutLoopMaxStates));
      else loop.delay = static_cast<int>(v);
    }
  }
  if (const ConfigNode* s = root.find("input_variance")) {
    if (number(*s, "input_variance", loop.input_variance, diags) && loop.input_variance < 0)
      diags.error(s->loc, "input_variance must be >= 0");
  }
  if (!diags.empty()) return false;
  if (auto e = motion::dropout_loop_error(loop); !e.empty()) {
    diags.error(root.loc, e);
    return false;
  }
  return true;
}

std::string taps_text(const std::vector<double>& a) {
  std::ostringstream s;
  s << std::setprecision(6) << "[";
  for (std::size_t i = 0; i < a.size(); ++i) s << (i ? ", " : "") << a[i];
  return s.str() + "]";
}

}  // namespace cmd_design_impl

int cmd_design_compensator(const DesignOptions& o) {
  using namespace cmd_design_impl;
  motion::DropoutLoop loop;
  Diagnostics diags;
  if (!read_loop(o.loop, loop, diags)) {
    for (const auto& d : diags.sorted()) std::cerr << d.text() << "\n";
    return kExitInvalid;
  }
  if (!(o.loss >= 0 && o.loss < 1)) {
    std::cerr << "--loss must be in [0, 1)\n";
    return kExitInvalid;
  }
  struct Row {
    std::string name;
    std::vector<double> taps;
    motion::LoopPower power;
  };
  std::vector<Row> rows;
  auto add = [&](std::string name, std::vector<double> taps) {
    const auto p = motion::dropout_loop_power(loop, taps, o.loss);
    rows.push_back({std::move(name), std::move(taps), p});
  };
  add("zero fill", {});
  add("hold (1-delay)", {1.0});
  for (const auto& t : o.taps) add("given", t);
  motion::DropoutDesign d;
  try {
    d = motion::design_dropout_compensator(loop, o.order, o.loss);
  } catch (const std::exception& e) {
    std::cerr << o.loop << ": " << e.what() << "\n";
    return kExitInvalid;
  }
  if (o.json) {
    nlohmann::json j;
    j["loss"] = o.loss;
    j["order"] = o.order;
    j["optimal"] = {{"taps", d.taps},
                    {"output_power", d.output_power},
                    {"gradient_norm", d.gradient_norm},
                    {"evaluations", d.evaluations},
                    {"start", d.start}};
    for (const auto& r : rows)
      j["compare"].push_back({{"name", r.name},
                              {"taps", r.taps},
                              {"ms_stable", r.power.ms_stable},
                              {"output_power", r.power.ms_stable ? nlohmann::json(r.power.output_power) : nlohmann::json()}});
    std::cout << j.dump(2) << "\n";
    return kExitOk;
  }
  std::cout << o.loop << ": plant order " << loop.plant.den.size() - 1 << ", delay " << loop.delay
            << (loop.delay == 1 ? " frame" : " frames") << ", white input of variance " << loop.input_variance
            << "; Bernoulli dropout rate " << o.loss << "\n\n";
  std::cout << std::left << std::setw(24) << "compensator" << std::setw(52) << "taps a1.." << "output power E[y^2]\n";
  auto line = [&](const std::string& name, const std::vector<double>& taps, bool stable, double power) {
    std::cout << std::left << std::setw(24) << name << std::setw(52) << taps_text(taps);
    if (stable) std::cout << std::setprecision(8) << power << "\n";
    else std::cout << "unbounded (not mean-square stable)\n";
  };
  for (const auto& r : rows) line(r.name, r.taps, r.power.ms_stable, r.power.output_power);
  line("optimal (Ling & Lemmon)", d.taps, true, d.output_power);
  std::cout << "\n|gradient| at the optimum " << std::setprecision(3) << d.gradient_norm << " (" << d.evaluations
            << " evaluations; best from the start '" << d.start << "')\n";
  std::cout << "\nOPTIMAL_COMPENSATOR: --set NAME.design=1 --set NAME.order=" << o.order;
  for (std::size_t i = 0; i < d.taps.size(); ++i)
    std::cout << " --set NAME.a" << i + 1 << "=" << std::setprecision(17) << d.taps[i];
  std::cout << "\n";
  return kExitOk;
}

}  // namespace syncplc::cli
