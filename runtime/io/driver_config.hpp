// Reading a driver's settings from its project-file entry: numbers with
// units, per-axis lists, durations, choices. Every problem is reported
// through DriverSetup::error with the value's file:line:col, and ok() turns
// false; the getters then return their defaults so reading can go on and one
// load reports every error.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/io_driver.hpp"

namespace syncplc {

class DriverConfig {
 public:
  // `keys`: the keys this driver type accepts besides name, type, task, bind.
  DriverConfig(const ConfigNode& cfg, DriverSetup& setup, std::string driver_type, std::vector<std::string> keys);
  // A map inside a driver's entry (a sim_ring's loss: or bus:): only `keys`;
  // name, type, task and bind belong to the driver itself.
  static DriverConfig section(const ConfigNode& cfg, DriverSetup& setup, std::string section, std::vector<std::string> keys);

  bool ok() const { return ok_; }
  bool has(const std::string& key) const { return cfg_.find(key) != nullptr; }
  const ConfigNode* node(const std::string& key) const { return cfg_.find(key); }
  void error(const SourceLoc& where, const std::string& message);

  // A quantity converted to `unit` ("" = dimensionless), checked against [min, max].
  double number(const std::string& key, const std::string& unit, double def,
                std::optional<double> min = std::nullopt, std::optional<double> max = std::nullopt);
  double number_at(const ConfigNode& n, const std::string& what, const std::string& unit,
                   std::optional<double> min = std::nullopt, std::optional<double> max = std::nullopt);
  // One value for every element or a list of exactly `count`; `defs` when absent.
  std::vector<double> numbers(const std::string& key, const std::string& unit, std::size_t count,
                              const std::vector<double>& defs, std::optional<double> min = std::nullopt,
                              std::optional<double> max = std::nullopt);
  std::int64_t integer(const std::string& key, std::int64_t def, std::int64_t min, std::int64_t max);
  std::int64_t duration_ns(const std::string& key, std::int64_t def, std::int64_t min, std::int64_t max);
  std::int64_t duration_at(const ConfigNode& n, const std::string& what);
  bool boolean(const std::string& key, bool def);
  std::string choice(const std::string& key, const std::vector<std::string>& options, const std::string& def);

  const std::string& type() const { return type_; }

 private:
  DriverConfig(const ConfigNode& cfg, DriverSetup& setup, std::string name, const std::vector<std::string>& keys,
               bool section);
  const ConfigNode& cfg_;
  DriverSetup& setup_;
  std::string type_;
  bool ok_ = true;
};

}  // namespace syncplc
