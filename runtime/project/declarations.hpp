// What a project file declares, as plain data: the output of reading
// (read_*.cpp), annotated by the checks (check_*.cpp), turned into a Program
// by build_program.cpp. Indices, not pointers, link the declarations.
//
// Stages of a load (loader.cpp):
//   1. read:  YAML tree -> Declarations (every section, each name once)
//   2. check: Declarations -> resolved connections, types, owners, values,
//             execution order (Wiring, BlockOrder), all errors of all checks
//   3. build: Declarations + Wiring + BlockOrder -> Program
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "runtime/core/block.hpp"
#include "runtime/core/force_table.hpp"
#include "runtime/core/io_driver.hpp"
#include "runtime/modbus/modbus_config.hpp"
#include "runtime/store/store_settings.hpp"
#include "runtime/core/program.hpp"
#include "runtime/project/contour_metric.hpp"

namespace syncplc {

inline constexpr int kBrokenSource = -2;  // an input wired to a declaration that failed

struct TaskDecl {
  TaskConfig cfg;
  SourceLoc loc;
  std::optional<SourceLoc> write_queue_loc;  // set by the project (else the default, which may grow)
};

struct TagDecl {
  Tag tag;
  std::string task;  // explicit owner, "" if none
  SourceLoc task_loc;
  SourceLoc address_loc;      // where its address: is written (overlaps are reported there)
  std::optional<ModbusPlace> modbus;  // its explicit Modbus place (else its direct address's, if any)
  std::optional<store::TrendSpec> trend;  // its trend: key (tag index set when the store settings are built)
  SourceLoc modbus_loc;       // the tag's modbus: key, where its overlaps are reported
  SourceLoc hmi_loc;          // its hmi: key
  bool modbus_failed = false;  // its modbus: key was wrong (reported): it takes no place at all
  bool init_from_cli = false;  // --set tag=value gave its initial value
  // Found by the checks:
  int writer_task = -1;
  std::string writer;  // "block x.Q", "driver io.ch"
  SourceLoc writer_loc;
  std::vector<int> reader_tasks;
};

// A list per pin, kept only for the pins that have one: element sources of
// array pins wired by element, constants and initial values. A block type
// has up to a dozen pins and few of them have a list; a vector per pin was
// a quarter of the loader's memory at 100,000 blocks (docs/benchmarks.md,
// section 6). A pin without a list reads as an empty one.
template <class T>
class PinLists {
 public:
  const std::vector<T>& operator[](std::size_t pin) const {
    for (const auto& [p, v] : lists_)
      if (p == pin) return v;
    static const std::vector<T> none;
    return none;
  }
  // The pin's list, made when it has none yet.
  std::vector<T>& of(std::size_t pin) {
    for (auto& [p, v] : lists_)
      if (p == pin) return v;
    return lists_.emplace_back(static_cast<std::uint32_t>(pin), std::vector<T>{}).second;
  }
  // (pin, list) of the pins that have one, in the order they were made.
  const std::vector<std::pair<std::uint32_t, std::vector<T>>>& lists() const { return lists_; }
  void clear() { lists_.clear(); }

 private:
  std::vector<std::pair<std::uint32_t, std::vector<T>>> lists_;
};

struct InstanceDecl {
  std::string name;
  const BlockTypeInfo* type = nullptr;
  int task = -1;
  std::optional<IecType> datatype;
  bool datatype_fixed = false;
  bool retain = false;      // retain: true (persistent implies it): the block's state survives a restart
  bool persistent = false;  // also survives loading a changed project
  SourceLoc retain_loc;     // where retain:/persistent: is written
  SourceLoc loc;
  // As written, by ParamDecl or pin index; few per instance, so kept sparse
  // (copies of the file's nodes: the tree is gone before the build).
  std::vector<std::pair<int, ConfigNode>> params;
  std::vector<std::pair<int, std::string>> param_override;  // --set instance.param=value
  std::vector<std::pair<int, ConfigNode>> inputs;           // constant inputs
  // Links as written (LinkDecl index, the target's name and where it is
  // written); the target's instance index is found by check_links.
  struct LinkRef {
    int link = -1;
    std::uint32_t element = 0;  // of a list link
    std::string target;
    SourceLoc loc;
    int instance = -1;
  };
  std::vector<LinkRef> links;
  const ConfigNode* param(std::size_t i) const { return find(params, i); }
  const ConfigNode* input(std::size_t pin) const { return find(inputs, pin); }
  const std::string* override_of(std::size_t i) const {
    for (const auto& [k, v] : param_override)
      if (static_cast<std::size_t>(k) == i) return &v;
    return nullptr;
  }
  // Filled by the checks:
  std::vector<int> source;                // connection index feeding each input pin, -1 none, kBrokenSource
  std::vector<std::uint32_t> pin_length;  // elements per pin (1 for a scalar), set from parameters
  PinLists<int> element_source;           // array input pins wired by element: connection feeding each element, -1 none
  bool params_ok = true;                  // parameters parsed (so array pin lengths are known)
  PinLists<Cell> pin_values;              // constants and pin inits by pin index
  std::vector<Cell> param_cells;                // by ParamDecl index
  bool values_ok = true;

 private:
  static const ConfigNode* find(const std::vector<std::pair<int, ConfigNode>>& v, std::size_t i) {
    for (const auto& [k, n] : v)
      if (static_cast<std::size_t>(k) == i) return &n;
    return nullptr;
  }
};

struct Endpoint {
  bool is_pin = false;
  int instance = -1;
  int pin = -1;
  int tag = -1;
  std::optional<std::uint32_t> element;  // 0-based
  SourceLoc loc;
  std::string text;
  // A variable of an ST instance (instance.path, not a pin of its type): an
  // element of its variables pin, of this type (runtime/st/vm/st_block.hpp).
  std::optional<IecType> variable_type;
};

// A connection as written: "a.OUT -> b.IN" or {from, to}.
struct ConnectionText {
  std::string src, dst;
  SourceLoc src_loc, dst_loc, loc;
};

struct ConnectionDecl {
  Endpoint src, dst;
  SourceLoc loc;
};

struct DriverDecl {
  std::string name;
  std::string type;
  int task = -1;
  std::unique_ptr<IoDriver> driver;
  std::vector<int> channel_tag;  // per channel, -1 unbound
  std::vector<SourceLoc> channel_loc;
  SourceLoc loc;
  std::string settings;  // DriverBinding::settings: type, period, seed, entry without bind
};

using RefList = std::vector<std::pair<std::string, SourceLoc>>;

struct StProject;  // read_st.hpp

struct Declarations {
  std::string file;
  std::shared_ptr<StProject> st;  // the project's Structured Text (sources:), its block types
  std::string name = "unnamed", version = "0";
  std::uint64_t seed = 1;
  std::size_t max_forces = kDefaultMaxForces;  // project: max_forces
  bool st_native = true;  // project: st_engine (native, or interpreter)
  std::vector<TaskDecl> tasks;
  std::vector<TagDecl> tags;
  std::vector<InstanceDecl> instances;
  std::vector<DriverDecl> drivers;
  std::vector<ConnectionText> connections;
  RefList traces, watch;
  RefList axis_errors;  // metrics: axis_errors
  std::int64_t metrics_from_ns = 0;
  ContourDecl metrics_contour;  // metrics: contour (contour_metric.hpp)
  ModbusConfig modbus;  // the modbus: section
  store::StoreSettings store;  // the store: section (trends gathered from the tags at the build)
  // Tag initial values given on the command line (--set tag=value), checked with the owners.
  std::vector<std::pair<int, std::string>> cli_tag_values;

  // One namespace for tags, instances and drivers; hashed (a project of
  // 100,000 blocks resolves 200,000 references).
  std::unordered_map<std::string, SourceLoc> names;
  std::unordered_map<std::string, int> task_by_name, tag_by_name, instance_by_name;
  std::set<std::string> failed_names;  // declarations already reported: no follow-on errors

  int task_index(const std::string& n) const { return find(task_by_name, n); }
  int tag_index(const std::string& n) const { return find(tag_by_name, n); }
  int instance_index(const std::string& n) const { return find(instance_by_name, n); }

 private:
  static int find(const std::unordered_map<std::string, int>& m, const std::string& n) {
    auto it = m.find(n);
    return it == m.end() ? -1 : it->second;
  }
};

// Found by the checks, used by the build.
struct Wiring {
  std::vector<ConnectionDecl> connections;
};

struct BlockOrder {
  std::vector<std::vector<int>> order;  // per task: instance indices, unit delays first
  std::vector<std::size_t> delays;      // per task: how many unit delays lead the order
};

}  // namespace syncplc
