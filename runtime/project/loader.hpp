// Loads a project file into a Program: parses, checks everything, reports
// every error at once as file:line:col, and builds the tasks' images and
// execution orders. A failed load returns no Program, so a running program
// is never replaced by one that did not load.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/core/io_driver.hpp"
#include "runtime/core/program.hpp"
#include "runtime/modbus/modbus_config.hpp"
#include "runtime/project/diagnostics.hpp"
#include "runtime/project/metrics.hpp"
#include "runtime/project/st_summary.hpp"
#include "runtime/store/source_file.hpp"
#include "runtime/store/store_settings.hpp"

namespace syncplc {

struct ParamOverride {
  std::string instance;
  std::string param;
  std::string value;
};

struct LoadOptions {
  std::optional<std::uint64_t> seed;       // overrides project.seed
  std::vector<ParamOverride> overrides;    // --set instance.param=value
  const BlockRegistry* blocks = nullptr;   // default: builtin_blocks()
  const DriverRegistry* drivers = nullptr; // default: builtin_drivers()
  // Set (by another thread) to give up between stages: a PLC that stops
  // while it loads a project for an online change does not wait for it.
  const std::atomic<bool>* cancel = nullptr;
  // The program will run in virtual time (VirtualClock): drivers with a link
  // to other nodes take their simulated one (DriverSetup::virtual_time), on
  // `bus` when the nodes of a system share one (runtime/project/system.hpp).
  bool virtual_time = false;
  std::shared_ptr<VirtualBus> bus;
};

struct LoadResult {
  std::unique_ptr<Program> program;  // null when diagnostics is not empty
  // What the project says beside the program (empty when it did not load):
  ModbusSettings modbus;    // the modbus: section and the tags' explicit places
  MetricsSettings metrics;  // the metrics: section, resolved in the program
  store::StoreSettings store;  // the store: section and the trended tags
  Diagnostics diagnostics;
  // Every file read, the project file first, then its include: files as
  // they were read (also when the load failed): what the project store keeps.
  std::vector<store::SourceFile> sources;
  StSummary st;  // the sources: and how they run
  bool ok() const { return program != nullptr; }
};

LoadResult load_project(const std::string& path, const LoadOptions& options = {});
// For tests: a project given as text; `name` stands for the file in messages.
LoadResult load_project_text(const std::string& text, const std::string& name, const LoadOptions& options = {});

// Parses "a.b=value" into an override; false on a malformed text.
bool parse_override(const std::string& text, ParamOverride& out);

}  // namespace syncplc
