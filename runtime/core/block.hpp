// The function-block interface: what a block type declares once (pins,
// parameters, documentation) and what an instance does every scan.
//
// A block type is registered with a BlockTypeInfo. When a project loads, the
// loader creates each instance through the type's factory, binds every pin to
// a cell of the task's process image, and from then on calls execute() once
// per scan. Pins are reached by their declaration index: in<T>(i), out<T>(i, v).
// execute() must not allocate, lock, log or do I/O.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/iec_type.hpp"

namespace syncplc {

enum class PinDir : std::uint8_t { In, Out };

// Longest array pin a block may declare through its length parameter.
inline constexpr std::uint32_t kMaxPinLength = 4096;

struct PinDecl {
  std::string name;
  PinDir dir = PinDir::In;
  // Exact: the pin has `type`. Otherwise the pin takes the instance's generic
  // type (one per instance, inferred from connections or set with `datatype:`),
  // which must belong to this class.
  TypeClass cls = TypeClass::Exact;
  IecType type = IecType::LREAL;
  std::string unit;          // SI-style unit text, "" for dimensionless
  bool required = false;     // an input that must be connected or given a value
  std::string doc;
  std::string init;          // value of an unconnected input ("" = the type's zero)
  // Array pin: ARRAY[1..n] OF type, n the value of this integer parameter of
  // the instance (set at load). "" = a scalar pin. The pin's elements occupy
  // consecutive cells; a block reaches element i (0-based) with in<T>(pin, i).
  std::string length_param;
  // The tuning input of this tunable parameter ("" = an ordinary pin). Added
  // by BlockRegistry::add, named <param>_in (see BlockGuard).
  std::string tunes;
  // The longest this array pin may be (an ST instance's variables: more).
  std::uint32_t max_length = kMaxPinLength;

  bool is_array() const { return !length_param.empty(); }
};

// The output every block type gets from BlockRegistry::add (IEC 61131-3 ENO):
// FALSE while an input is NaN or infinite (the block then does not execute
// and its outputs hold their last valid values) or a tuning input is invalid.
inline constexpr const char* kEnoPin = "ENO";
// Suffix of the tuning input BlockRegistry::add gives each tunable parameter.
inline constexpr const char* kTuningSuffix = "_in";

struct ParamDecl {
  std::string name;
  IecType type = IecType::LREAL;
  std::string default_value;  // literal; "" means the parameter is mandatory
  std::optional<double> min;  // valid range, inclusive, in `unit`
  std::optional<double> max;
  std::string unit;
  std::string doc;
  // A tunable parameter (a gain, a limit, a feed) may change while the block
  // runs: on an online change the running instance keeps its state and takes
  // the new value through Block::retune_from. Any other parameter is structure:
  // changing it starts the instance fresh.
  bool tunable = false;
};

// A link: a parameter whose value names another block instance of the same
// task, of type `target_type`, that this one works through (a PLCopen
// motion block's AXIS_REF: `params: {axis: x}` names the MC_AXIS instance
// x). The loader checks the name and the type and calls Block::link with
// the target; the target executes before the blocks linked to it.
// A list link (`length_param` set) names as many instances as that integer
// parameter says: `params: {n: 3, Axes: [x, y, z]}`.
struct LinkDecl {
  std::string name;
  std::string target_type;
  std::string doc;
  std::string length_param{};  // "" = one instance
  // At most one instance of the linking type may name a given target (one
  // MC_Power per axis): `exclusive` says why, "" = any number may.
  std::string exclusive{};
};

struct ScanContext;
class BlockSetup;

// What the runtime checks around execute() for one instance (finite_guard.hpp):
// built by the factory BlockRegistry::add wraps around every type's factory,
// so no block type can miss it. Sized at load; the scan only reads and flags.
struct BlockGuard {
  struct Span {            // a REAL or LREAL input: pin, elements, REAL or not
    std::int32_t pin = 0;
    std::uint32_t n = 1;
    bool single = false;   // REAL (float); else LREAL (double)
  };
  struct Tuning {          // a connected tuning input <param>_in
    std::int32_t pin = 0;
    std::int32_t param = 0;
    IecType type = IecType::LREAL;
    double min = 0, max = 0;  // the ParamDecl range (+-inf when open)
    double seen = 0;          // the pin's value when last evaluated
    bool ok = true;           // that value was valid and taken
  };
  std::vector<Span> reals;
  std::vector<Tuning> tuning;
  std::int32_t eno = -1;      // pin index of ENO
  bool unit_delay = false;    // inputs checked at end_of_scan instead
  bool held = false;          // unit delay: the last end_of_scan was skipped
};

class Block {
 public:
  virtual ~Block() = default;
  // One scan. ctx.now_ns is the planned release time of the scan. noexcept
  // by contract: nothing may escape a scan (a block that cannot compute
  // raises ctx.fault and holds its last valid output).
  virtual void execute(ScanContext& ctx) noexcept = 0;
  // Unit-delay blocks only (BlockTypeInfo::unit_delay): called after every
  // block of the task has executed; store the input for the next scan here.
  virtual void end_of_scan() noexcept {}
  // Online change of an instance whose tunable parameters (ParamDecl::tunable)
  // changed and nothing else: `fresh` is a new instance of the same type built
  // from the new parameters; take its tunable values and keep every state
  // variable, bumplessly (the output must not jump because a gain changed).
  // Runs on the task's thread between two scans: no allocation, no I/O.
  virtual void retune_from(const Block& fresh) noexcept { (void)fresh; }
  // Online change of an instance whose wiring changed where its factory
  // read it (BlockSetup::connected: an optional operand wired in, a velocity
  // input that replaces a derived one): `fresh` is a new instance of the same
  // type built with the new wiring; take every choice the factory made from
  // the wiring and keep every state variable. Only for types that declare
  // BlockTypeInfo::rewire; the others are re-created (instance_signature.hpp).
  // Runs on the task's thread between two scans: no allocation, no I/O.
  virtual void rewire_from(const Block& fresh) noexcept { (void)fresh; }
  // A connected tuning input <param>_in changed to `value` (already finite and
  // within the ParamDecl range): take it bumplessly, through the same code as
  // retune_from, and return true; return false to refuse it (a value invalid
  // with the other parameters, e.g. out_min >= out_max), keeping the last
  // valid value. Called on the scan path: no allocation.
  virtual bool tune(int param, double value) noexcept {
    (void)param;
    (void)value;
    return false;
  }
  // Link `link` (BlockTypeInfo::links index; `element`, 0-based, of a list
  // link, else 0) reaches `target`, an instance of the declared target
  // type: called before the first scan and again
  // after every online change's switch of the task (the target may then be
  // another object: re-created, or the kept instance swapped in). Runs
  // between two scans on the task's thread: no allocation, no I/O.
  virtual void link(int link, std::uint32_t element, Block& target) noexcept {
    (void)link;
    (void)element;
    (void)target;
  }

  // Retain (docs/store.md, "Retained block instances"): a block whose state
  // is worth keeping across a restart (a counter's count, a unit delay's
  // sample) exposes it as retain_cells() cells, a number fixed at creation.
  // save_retain runs on the scan path into cells the task publishes (no
  // allocation); load_retain runs before the first scan. retain_layout()
  // changes whenever the meaning of the cells changes, so a stored state of
  // an older layout is not restored. 0 cells: nothing to retain (a project
  // declaring such an instance retain is refused at load).
  virtual std::uint32_t retain_cells() const noexcept { return 0; }
  virtual std::uint32_t retain_layout() const noexcept { return 1; }
  virtual void save_retain(Cell* out) const noexcept { (void)out; }
  virtual void load_retain(const Cell* in) noexcept { (void)in; }

  template <class T>
  T in(int pin) const noexcept { return pins_[pin]->get<T>(); }
  template <class T>
  void out(int pin, T v) noexcept { pins_[pin]->set<T>(v); }
  // Element i (0-based) of an array pin.
  template <class T>
  T in(int pin, std::uint32_t i) const noexcept { return pins_[pin][i].get<T>(); }
  template <class T>
  void out(int pin, std::uint32_t i, T v) noexcept { pins_[pin][i].set<T>(v); }
  Cell* pin_cell(int pin) const noexcept { return pins_[pin]; }

  // Bound by the loader (or a test harness) before the first scan, and again
  // when an online change moves a kept instance into the new program (on
  // the task's thread, between two scans).
  void bind_pins(Cell* const* pins) noexcept {
    pins_ = pins;
    pins_bound();
  }

  BlockGuard& guard() noexcept { return guard_; }

 protected:
  // The pins were (re)bound: a block that keeps state in its pins' cells
  // (an ST instance's frame) takes them here. No allocation.
  virtual void pins_bound() noexcept {}

 public:
  const BlockGuard& guard() const noexcept { return guard_; }

 private:
  Cell* const* pins_ = nullptr;
  BlockGuard guard_;
};

using BlockFactory = std::function<std::unique_ptr<Block>(BlockSetup&)>;

struct BlockTypeInfo {
  std::string name;      // e.g. "TON"
  std::string category;  // e.g. "IEC timers"
  std::string doc;       // one paragraph: behaviour, equations
  std::string reference; // standard or paper and equation numbers
  std::vector<PinDecl> pins;
  std::vector<ParamDecl> params;
  // For generic types: the default when nothing fixes the instance's type
  // (std::nullopt: the type must be inferable or given).
  std::optional<IecType> default_datatype;
  // The outputs depend only on earlier scans' inputs (a one-scan delay), so a
  // connection loop through this block is allowed.
  bool unit_delay = false;
  BlockFactory create;
  // Block::rewire_from takes what the factory read of the wiring from a
  // fresh instance: an online change that rewires such a pin keeps the
  // instance's state (otherwise it re-creates the instance). Last, so that
  // types written as one brace list of the fields before it stay as they are.
  bool rewire = false;
  // A type whose instances have variables beyond their pins (an ST POU's,
  // runtime/st/vm/st_block.hpp), kept in the array output pin
  // `variables_pin`: `variable` resolves a path below the instance
  // ("count", "fb.q", "arr[3]", "s.x") to an element of that pin and its
  // type, or nullopt with the reason. Users address it as instance.path.
  struct Variable {
    std::uint32_t element = 0;
    IecType type = IecType::LREAL;
    // Why a write from outside would not take ("" when it would): a VAR
    // CONSTANT, a VAR_TEMP.
    std::string read_only{};
    // A subrange's bounds: a write outside them is refused.
    std::optional<std::pair<std::int64_t, std::int64_t>> range{};
  };
  int variables_pin = -1;
  std::function<std::optional<Variable>(std::string_view path, std::string* error)> variable{};
  // Why a project may not make an instance of this type ("" when it may): an
  // ST POU with a VAR_IN_OUT, which only a calling POU can bind.
  std::string not_instanceable{};
  // Its variables as leaves (elementary values, strings, arrays of them),
  // for an online change that re-creates an instance to carry over those
  // whose path and type are unchanged (program_change.cpp).
  struct VariableLeaf {
    std::string path;  // "count", "fb.q", "hist"
    std::string type;  // as the compiler spells it: "DINT", "ARRAY[1..3] OF LREAL", "STRING[20]"
    std::uint32_t element = 0, count = 1;  // cells of the variables pin
    bool retain = false;      // declared RETAIN (or inside a RETAIN instance): kept across a restart
    bool persistent = false;  // declared PERSISTENT: also across loading a changed project
  };
  std::vector<VariableLeaf> variable_leaves{};
  // Its variables to monitor, element by element with their real indices
  // ("count", "t.ET", "grid[1, 2]", "pts[2].x"; not the pins, not strings),
  // made once with the type; at most kMaxMonitored, and how many more.
  struct Monitored {
    std::string path;
    std::uint32_t element = 0;
    IecType type = IecType::LREAL;
  };
  static constexpr std::size_t kMaxMonitored = 1024;
  std::vector<Monitored> monitored{};
  std::size_t monitored_left_out = 0;
  // Parameters that name another instance (LinkDecl); given in a project's
  // params: like a parameter, each one required.
  std::vector<LinkDecl> links{};

  int link_index(std::string_view link) const;

  int pin_index(std::string_view pin) const;
  // Whether instance.member names one of the type's variables rather than a
  // pin: a type with variables, and a member that is not an input pin (an
  // output of an ST FB is its variable too, and setting the variable is what
  // a test means; an input is copied in from its pin at every scan).
  bool names_variable(std::string_view member) const {
    if (!variable) return false;
    const int p = pin_index(member.substr(0, member.find_first_of(".[")));
    return p < 0 || pins[static_cast<std::size_t>(p)].dir == PinDir::Out;
  }
  int param_index(std::string_view param) const;
  bool is_generic() const;
};

// What a factory sees of the instance being created: its parameters, which
// pins are wired, its resolved generic type. Errors reported here make the
// load fail with the instance's location.
class BlockSetup {
 public:
  virtual ~BlockSetup() = default;
  virtual const std::string& instance_name() const = 0;
  virtual const BlockTypeInfo& type() const = 0;
  virtual IecType datatype() const = 0;                   // generic type (LREAL if not generic)
  virtual Cell param_cell(int index) const = 0;           // by ParamDecl index
  virtual bool connected(int pin) const = 0;               // wired (whole or any element) or given a constant
  virtual std::uint32_t pin_length(int pin) const = 0;     // elements of an array pin, 1 for a scalar
  virtual std::int64_t task_period_ns() const = 0;
  // The task's watchdog time, 0 when it has none (ST's loop budget follows it).
  virtual std::int64_t task_watchdog_ns() const { return 0; }
  virtual std::uint64_t seed() const = 0;                  // project seed mixed with instance name
  virtual void error(const std::string& message) = 0;

  // A factory's parameter by name. A name the type does not declare (a
  // misspelt one) is reported through unknown_param, a load error, and reads T{}.
  template <class T>
  T param(std::string_view name) const {
    const int i = type().param_index(name);
    if (i < 0) {
      unknown_param(name);
      return T{};
    }
    return param_cell(i).template get<T>();
  }
  virtual void unknown_param(std::string_view name) const = 0;
};

enum class EventKind : std::uint8_t {
  WatchdogTrip,
  TaskStopped,
  SafeStateApplied,
  BlockFault,       // a block met a condition it cannot compute (e.g. integer division by zero)
  ScanOverrun,
  QueueOverflow,
  DriverFault,
  Info,
  ScanHung,         // raised by the supervisor: a scan ran past its limit and has not ended
  // An overrun whose cause is a late start: the scan was shorter than its
  // period but began so late that it ended after the next release (value:
  // how late it started, s). Logged as kind "overrun" like ScanOverrun.
  ScanLate,
};
std::string_view event_kind_name(EventKind k);

struct Event {
  std::int64_t time_ns = 0;  // planned release time of the scan that raised it
  std::uint16_t task = 0;
  std::int32_t block = -1;   // index in the task's execution order, -1 for the task itself
  EventKind kind = EventKind::Info;
  const char* message = "";  // static text: raising an event never allocates
  double value = 0;
  // The raising task's scan count (Task::scan_count) when it was raised, set
  // by Task::push (a plain copy: real-time safe); kNoScan from the supervisor.
  static constexpr std::uint64_t kNoScan = ~std::uint64_t{0};
  std::uint64_t scan = kNoScan;
};

class EventSink {
 public:
  virtual ~EventSink() = default;
  virtual void push(const Event& e) noexcept = 0;  // lock-free, never blocks
};

// Per-scan context handed to every block.
struct ScanContext {
  std::int64_t now_ns = 0;       // planned release of this scan: the IEC time base
  std::int64_t dt_ns = 0;        // since the previous scan's planned release (the period on the first)
  std::uint64_t scan = 0;        // 0 on the first scan
  bool virtual_time = true;
  // Real time: the planned release on CLOCK_REALTIME (ns since the Unix
  // epoch), what nodes on one grid compare (docs/dds.md); 0 in virtual time.
  std::int64_t realtime_ns = 0;
  std::int64_t consumed_ns = 0;  // virtual execution time consumed so far in this scan
  std::uint16_t task = 0;
  std::int32_t block = -1;       // index of the executing block, set by the executor
  EventSink* events = nullptr;
  // Set by a driver that asks for its task to stop with its safe outputs (a
  // Modbus client group's reaction `stop`, docs/modbus-client.md): after this
  // scan the task applies its safe values and stops, as a safe_stop watchdog
  // does. Static text: it becomes the TaskStopped event's message.
  // Mutable: drivers get the context as const (IoDriver::latch_inputs).
  mutable const char* stop_request = nullptr;

  void request_stop(const char* why) const noexcept { stop_request = why; }
  void fault(const char* message, double value = 0) noexcept {
    if (events) events->push(Event{now_ns, task, block, EventKind::BlockFault, message, value});
  }
};

class BlockRegistry {
 public:
  BlockRegistry() = default;
  // A registry that adds types to `base` (a project's own block types beside
  // the built-in ones): find() looks here first, then in base.
  explicit BlockRegistry(const BlockRegistry* base) : base_(base) {}
  // Throws std::logic_error on a duplicate or inconsistent declaration.
  void add(BlockTypeInfo info);
  const BlockTypeInfo* find(std::string_view name) const;
  std::vector<const BlockTypeInfo*> all() const;  // sorted by category, then name

 private:
  std::vector<std::unique_ptr<BlockTypeInfo>> types_;
  const BlockRegistry* base_ = nullptr;
};

}  // namespace syncplc
