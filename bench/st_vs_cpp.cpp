// Compiled Structured Text against hand-written C++ (issue 23), side by side
// in one process (docs/benchmarks.md section 17):
//   BM_Pid_St / _Cpp            a PID with a clamping integrator and output limits on LREAL
//   BM_StateMachine_St / _Cpp   a 20-state CASE machine: inputs, time in state, counters
//   BM_ArrayLoop_St / _Cpp      a FOR over ARRAY[0..999] OF LREAL: scaling, sum, mean, peak
//   BM_Strings_St / _Cpp        a message on STRING[80]: CONCAT, INT_TO_STRING, LEN, FIND, LEFT, MID
//   BM_Call_St / _Cpp           y := x: what calling a block costs either way (a reference)
//   BM_Load10k                  parse + check + compile of a generated 10,000-line source
// One iteration is one scan of one instance. Both sides are a Block called
// through execute_guarded (runtime/core/finite_guard.hpp) as the task calls
// every block, so they pay the same calling cost: the C++ block reads its
// pins' cells; the ST one is the VM instance of the FUNCTION_BLOCK, whose
// input cells the benchmark writes in its frame before the call (as the
// runtime copies pins), and whose execute() is Instance::scan. The inputs
// change every scan (a table of 4096 seeded sets), and before any timing the
// two sides run the same 20,000 scans and must give the same outputs bit for
// bit (the program exits with an error otherwise). The aim: ST within 3x of
// C++ on each case, and loading 10,000 lines in under 1 s.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/core/finite_guard.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"
#include "runtime/st/vm/block_signatures.hpp"
#include "runtime/st/vm/codegen.hpp"
#include "runtime/st/vm/instance.hpp"
#include "runtime/st/vm/listing.hpp"
#include "runtime/st/vm/st_string.hpp"
#include "runtime/st/vm/var_path.hpp"
#include "runtime/st/vm/vm.hpp"

namespace {

using namespace syncplc;
namespace vm = syncplc::st::vm;

constexpr int kInputSets = 4096;  // a power of two: iteration & (kInputSets - 1)
constexpr int kCheckScans = 20'000;
constexpr std::int64_t kPeriodNs = 10'000'000;
constexpr std::int64_t kLoopBudget = 1'000'000;

// ---------------------------------------------------------------------------
// The ST side.

class NullSink final : public EventSink {
 public:
  void push(const Event&) noexcept override { ++events; }
  std::uint64_t events = 0;
};

// Parse, check, compile; throws with the first error.
struct StProgram {
  std::vector<std::unique_ptr<st::ParseResult>> parsed;
  st::CheckedProgram checked;
  std::shared_ptr<const vm::Module> module;

  StProgram(const std::string& source, vm::Engine engine) {
    parsed.push_back(std::make_unique<st::ParseResult>(st::parse(source, SourceFile("bench.st"))));
    if (!parsed.back()->ok()) throw std::runtime_error("parse: " + parsed.back()->diagnostics.list().front().text());
    checked = st::check({&parsed.back()->unit}, vm::block_signatures(builtin_blocks()));
    if (!checked.ok()) throw std::runtime_error("check: " + checked.diagnostics.sorted().front().text());
    st::StDiagnostics diags;
    auto m = vm::compile(checked, &builtin_blocks(), diags);
    if (!m || !diags.list().empty())
      throw std::runtime_error("compile: " + (diags.list().empty() ? std::string("failed") : diags.list().front().text()));
    vm::set_engine(*m, engine);
#if defined(__x86_64__)
    if (engine == vm::Engine::Native && vm::native_pous(*m) != m->pous.size())
      throw std::runtime_error("native code could not be made for every POU");
#endif
    module = std::move(m);
  }
};

// An instance of an ST FUNCTION_BLOCK as a block of the task's graph.
class StBlock final : public Block {
 public:
  StBlock(const std::string& source, const std::string& fb, vm::Engine engine = vm::Engine::Native)
      : program_(source, engine) {
    const int p = program_.module->find(fb);
    if (p < 0) throw std::runtime_error("no POU " + fb);
    pou_ = static_cast<std::uint32_t>(p);
    instance_ = std::make_unique<vm::Instance>(program_.module, pou_, vm::InstanceSetup{"bench", kPeriodNs, 1});
  }
  void execute(ScanContext& ctx) noexcept override { instance_->scan(ctx, kLoopBudget); }

  // The cell of a variable (resolved once, before the scans).
  Cell* cell(const std::string& path) {
    std::string why;
    const auto r = vm::resolve_path(*program_.module, pou_, path, &why);
    if (!r) throw std::runtime_error(path + ": " + why);
    return instance_->frame() + r->at;
  }
  const vm::Instance& instance() const { return *instance_; }
  std::string listing() const { return vm::listing(*program_.module, pou_); }

 private:
  StProgram program_;
  std::uint32_t pou_ = 0;
  std::unique_ptr<vm::Instance> instance_;
};

// ---------------------------------------------------------------------------
// The C++ side: pins bound to cells, as the loader binds a built-in block's.

template <int N>
struct PinCells {
  Cell cells[N] = {};
  Cell* pins[N] = {};
  PinCells() {
    for (int k = 0; k < N; ++k) pins[k] = &cells[k];
  }
};

// ---- the calling cost: one input copied to one output ----

const char* const kCallSt = R"(
FUNCTION_BLOCK Pass
VAR_INPUT
  x : LREAL;
END_VAR
VAR_OUTPUT
  y : LREAL;
END_VAR
y := x;
END_FUNCTION_BLOCK
)";

class PassCpp final : public Block {
 public:
  enum Pin { kX, kY, kPins };
  void execute(ScanContext&) noexcept override { out<double>(kY, in<double>(kX)); }
};

struct PassCells {
  Cell *x, *y;
};
PassCells pass_cells(StBlock& b) { return {b.cell("x"), b.cell("y")}; }
PassCells pass_cells(PinCells<PassCpp::kPins>& p) { return {p.cells + PassCpp::kX, p.cells + PassCpp::kY}; }
inline void put(const PassCells& c, double x) { c.x->set(x); }

std::vector<double>& pass_inputs() {
  static std::vector<double> v = [] {
    std::vector<double> x(kInputSets);
    for (int k = 0; k < kInputSets; ++k) x[k] = 0.25 * k;
    return x;
  }();
  return v;
}

// ---- PID with anti-windup ----

const char* const kPidSt = R"(
FUNCTION_BLOCK PidAw
VAR_INPUT
  sp, pv : LREAL;
  kp, ki, kd : LREAL;
  dt : LREAL;
  out_min, out_max : LREAL;
  reset : BOOL;
END_VAR
VAR_OUTPUT
  out : LREAL;
  saturated : BOOL;
END_VAR
VAR
  integral, last_pv : LREAL;
END_VAR
VAR_TEMP
  err, deriv, u : LREAL;
END_VAR
IF reset THEN
  integral := 0.0;
  last_pv := pv;
END_IF;
err := sp - pv;
(* The clamping integrator: it never winds up beyond the output's range. *)
integral := integral + ki * err * dt;
IF integral > out_max THEN
  integral := out_max;
ELSIF integral < out_min THEN
  integral := out_min;
END_IF;
deriv := (pv - last_pv) / dt;  (* on the measurement: no kick on a setpoint step *)
last_pv := pv;
u := kp * err + integral - kd * deriv;
IF u > out_max THEN
  out := out_max;
  saturated := TRUE;
ELSIF u < out_min THEN
  out := out_min;
  saturated := TRUE;
ELSE
  out := u;
  saturated := FALSE;
END_IF;
END_FUNCTION_BLOCK
)";

class PidCpp final : public Block {
 public:
  enum Pin { kSp, kPv, kKp, kKi, kKd, kDt, kOutMin, kOutMax, kReset, kOut, kSaturated, kPins };
  void execute(ScanContext&) noexcept override {
    const double sp = in<double>(kSp), pv = in<double>(kPv);
    const double kp = in<double>(kKp), ki = in<double>(kKi), kd = in<double>(kKd), dt = in<double>(kDt);
    const double out_min = in<double>(kOutMin), out_max = in<double>(kOutMax);
    if (in<bool>(kReset)) {
      integral_ = 0.0;
      last_pv_ = pv;
    }
    const double err = sp - pv;
    integral_ = integral_ + ki * err * dt;
    if (integral_ > out_max) integral_ = out_max;
    else if (integral_ < out_min) integral_ = out_min;
    const double deriv = (pv - last_pv_) / dt;
    last_pv_ = pv;
    const double u = kp * err + integral_ - kd * deriv;
    if (u > out_max) {
      out<double>(kOut, out_max);
      out<bool>(kSaturated, true);
    } else if (u < out_min) {
      out<double>(kOut, out_min);
      out<bool>(kSaturated, true);
    } else {
      out<double>(kOut, u);
      out<bool>(kSaturated, false);
    }
  }

 private:
  double integral_ = 0, last_pv_ = 0;
};

struct PidInput {
  double sp, pv, kp, ki, kd, dt, out_min, out_max;
  bool reset;
};

std::vector<PidInput> pid_inputs() {
  std::mt19937_64 g(23);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<PidInput> v(kInputSets);
  double pv = 0, sp = 50;
  for (int k = 0; k < kInputSets; ++k) {
    if (u(g) < 0.01) sp = 100 * u(g);
    pv += (sp - pv) * 0.05 + (u(g) - 0.5);
    v[k] = {sp, pv, 2.0 + u(g) * 0.01, 0.5, 0.05, 0.01, -20.0, 20.0, k == 0 || u(g) < 0.001};
  }
  return v;
}

// Where the inputs go and the outputs come from, for both sides.
struct PidCells {
  Cell *sp, *pv, *kp, *ki, *kd, *dt, *out_min, *out_max, *reset, *out, *saturated;
};

PidCells pid_cells(StBlock& b) {
  return {b.cell("sp"),      b.cell("pv"),      b.cell("kp"),    b.cell("ki"),  b.cell("kd"),       b.cell("dt"),
          b.cell("out_min"), b.cell("out_max"), b.cell("reset"), b.cell("out"), b.cell("saturated")};
}
PidCells pid_cells(PinCells<PidCpp::kPins>& p) {
  Cell* c = p.cells;
  return {c + PidCpp::kSp,     c + PidCpp::kPv,     c + PidCpp::kKp,    c + PidCpp::kKi,
          c + PidCpp::kKd,     c + PidCpp::kDt,     c + PidCpp::kOutMin, c + PidCpp::kOutMax,
          c + PidCpp::kReset,  c + PidCpp::kOut,    c + PidCpp::kSaturated};
}

inline void put(const PidCells& c, const PidInput& in) {
  c.sp->set(in.sp);
  c.pv->set(in.pv);
  c.kp->set(in.kp);
  c.ki->set(in.ki);
  c.kd->set(in.kd);
  c.dt->set(in.dt);
  c.out_min->set(in.out_min);
  c.out_max->set(in.out_max);
  c.reset->set(in.reset);
}

// ---- a 20-state CASE machine ----

const char* const kStateMachineSt = R"(
FUNCTION_BLOCK Station
VAR_INPUT
  start, stop, sensor_a, sensor_b, part_present : BOOL;
  level : LREAL;
  dt : TIME;
END_VAR
VAR_OUTPUT
  state : INT;
  motor, valve, clamp, alarm : BOOL;
  parts : DINT;
  retries : INT;
  transitions : DINT;
END_VAR
VAR
  t_state : TIME;
  prev : INT;
END_VAR
t_state := t_state + dt;
prev := state;
IF stop AND state <> 0 THEN
  state := 19;
END_IF;
CASE state OF
  0: (* idle *)
    IF start THEN state := 1; END_IF;
  1: (* wait for the carrier *)
    IF sensor_a THEN state := 2; ELSIF t_state > T#2s THEN state := 19; END_IF;
  2: (* feed *)
    motor := TRUE;
    IF part_present THEN state := 3; END_IF;
  3: (* run on a little *)
    IF t_state >= T#100ms THEN motor := FALSE; state := 4; END_IF;
  4: (* clamp *)
    clamp := TRUE;
    IF sensor_b THEN
      state := 5;
    ELSIF t_state > T#500ms THEN
      retries := retries + 1;
      IF retries > 3 THEN state := 19; ELSE state := 3; END_IF;
    END_IF;
  5: (* fill *)
    valve := TRUE;
    IF level > 80.0 THEN state := 6; END_IF;
  6: (* settle *)
    valve := FALSE;
    IF t_state >= T#200ms THEN state := 7; END_IF;
  7: (* drain check *)
    IF level < 20.0 THEN state := 8; ELSIF level > 95.0 THEN state := 19; END_IF;
  8: (* unclamp *)
    clamp := FALSE;
    state := 9;
  9: (* count the part *)
    parts := parts + 1;
    retries := 0;
    state := 10;
  10: (* a batch of ten? *)
    IF parts MOD 10 = 0 THEN state := 11; ELSE state := 12; END_IF;
  11: (* batch pause *)
    IF t_state >= T#1s THEN state := 12; END_IF;
  12: (* wait for the exit *)
    IF sensor_a AND NOT sensor_b THEN state := 13; END_IF;
  13: (* eject *)
    motor := TRUE;
    IF NOT part_present THEN state := 14; END_IF;
  14: (* run out *)
    IF t_state >= T#50ms THEN motor := FALSE; state := 15; END_IF;
  15: (* again? *)
    IF start THEN state := 16; ELSE state := 0; END_IF;
  16: (* rinse needed? *)
    IF level > 50.0 THEN state := 17; ELSE state := 18; END_IF;
  17: (* rinse *)
    valve := TRUE;
    IF level < 40.0 THEN valve := FALSE; state := 18; END_IF;
  18: (* next carrier *)
    state := 1;
  19: (* fault: everything off until acknowledged *)
    alarm := TRUE;
    motor := FALSE;
    valve := FALSE;
    clamp := FALSE;
    IF NOT stop AND start AND t_state >= T#1s THEN
      alarm := FALSE;
      retries := 0;
      state := 0;
    END_IF;
END_CASE;
IF state <> prev THEN
  t_state := T#0s;
  transitions := transitions + 1;
END_IF;
END_FUNCTION_BLOCK
)";

class StationCpp final : public Block {
 public:
  enum Pin {
    kStart, kStop, kSensorA, kSensorB, kPartPresent, kLevel, kDt,
    kState, kMotor, kValve, kClamp, kAlarm, kParts, kRetries, kTransitions, kPins
  };
  void execute(ScanContext&) noexcept override {
    const bool start = in<bool>(kStart), stop = in<bool>(kStop), sensor_a = in<bool>(kSensorA);
    const bool sensor_b = in<bool>(kSensorB), part_present = in<bool>(kPartPresent);
    const double level = in<double>(kLevel);
    constexpr std::int64_t ms = 1'000'000;
    t_state_ += in<std::int64_t>(kDt);
    const std::int16_t prev = state_;
    if (stop && state_ != 0) state_ = 19;
    switch (state_) {
      case 0:
        if (start) state_ = 1;
        break;
      case 1:
        if (sensor_a) state_ = 2;
        else if (t_state_ > 2000 * ms) state_ = 19;
        break;
      case 2:
        motor_ = true;
        if (part_present) state_ = 3;
        break;
      case 3:
        if (t_state_ >= 100 * ms) {
          motor_ = false;
          state_ = 4;
        }
        break;
      case 4:
        clamp_ = true;
        if (sensor_b) {
          state_ = 5;
        } else if (t_state_ > 500 * ms) {
          retries_ = static_cast<std::int16_t>(retries_ + 1);
          state_ = retries_ > 3 ? 19 : 3;
        }
        break;
      case 5:
        valve_ = true;
        if (level > 80.0) state_ = 6;
        break;
      case 6:
        valve_ = false;
        if (t_state_ >= 200 * ms) state_ = 7;
        break;
      case 7:
        if (level < 20.0) state_ = 8;
        else if (level > 95.0) state_ = 19;
        break;
      case 8:
        clamp_ = false;
        state_ = 9;
        break;
      case 9:
        parts_ = static_cast<std::int32_t>(static_cast<std::uint32_t>(parts_) + 1u);
        retries_ = 0;
        state_ = 10;
        break;
      case 10:
        state_ = parts_ % 10 == 0 ? 11 : 12;
        break;
      case 11:
        if (t_state_ >= 1000 * ms) state_ = 12;
        break;
      case 12:
        if (sensor_a && !sensor_b) state_ = 13;
        break;
      case 13:
        motor_ = true;
        if (!part_present) state_ = 14;
        break;
      case 14:
        if (t_state_ >= 50 * ms) {
          motor_ = false;
          state_ = 15;
        }
        break;
      case 15:
        state_ = start ? 16 : 0;
        break;
      case 16:
        state_ = level > 50.0 ? 17 : 18;
        break;
      case 17:
        valve_ = true;
        if (level < 40.0) {
          valve_ = false;
          state_ = 18;
        }
        break;
      case 18:
        state_ = 1;
        break;
      case 19:
        alarm_ = true;
        motor_ = valve_ = clamp_ = false;
        if (!stop && start && t_state_ >= 1000 * ms) {
          alarm_ = false;
          retries_ = 0;
          state_ = 0;
        }
        break;
      default: break;
    }
    if (state_ != prev) {
      t_state_ = 0;
      transitions_ = static_cast<std::int32_t>(static_cast<std::uint32_t>(transitions_) + 1u);
    }
    out<std::int16_t>(kState, state_);
    out<bool>(kMotor, motor_);
    out<bool>(kValve, valve_);
    out<bool>(kClamp, clamp_);
    out<bool>(kAlarm, alarm_);
    out<std::int32_t>(kParts, parts_);
    out<std::int16_t>(kRetries, retries_);
    out<std::int32_t>(kTransitions, transitions_);
  }

 private:
  std::int64_t t_state_ = 0;
  std::int16_t state_ = 0, retries_ = 0;
  std::int32_t parts_ = 0, transitions_ = 0;
  bool motor_ = false, valve_ = false, clamp_ = false, alarm_ = false;
};

struct StationInput {
  bool start, stop, sensor_a, sensor_b, part_present;
  double level;
};

std::vector<StationInput> station_inputs() {
  std::mt19937_64 g(2323);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<StationInput> v(kInputSets);
  double level = 50;
  for (int k = 0; k < kInputSets; ++k) {
    level = std::clamp(level + (u(g) - 0.5) * 20, 0.0, 100.0);
    v[k] = {u(g) < 0.7, u(g) < 0.002, u(g) < 0.5, u(g) < 0.3, u(g) < 0.5, level};
  }
  return v;
}

constexpr const char* kStationInputs[] = {"start", "stop", "sensor_a", "sensor_b", "part_present", "level", "dt"};
constexpr const char* kStationOutputs[] = {"state", "motor", "valve", "clamp", "alarm", "parts", "retries", "transitions"};

struct StationCells {
  Cell* in[7];
  Cell* out[8];
};

StationCells station_cells(StBlock& b) {
  StationCells c{};
  for (int k = 0; k < 7; ++k) c.in[k] = b.cell(kStationInputs[k]);
  for (int k = 0; k < 8; ++k) c.out[k] = b.cell(kStationOutputs[k]);
  return c;
}
StationCells station_cells(PinCells<StationCpp::kPins>& p) {
  StationCells c{};
  for (int k = 0; k < 7; ++k) c.in[k] = p.cells + k;
  for (int k = 0; k < 8; ++k) c.out[k] = p.cells + StationCpp::kState + k;
  return c;
}

inline void put(const StationCells& c, const StationInput& in) {
  c.in[0]->set(in.start);
  c.in[1]->set(in.stop);
  c.in[2]->set(in.sensor_a);
  c.in[3]->set(in.sensor_b);
  c.in[4]->set(in.part_present);
  c.in[5]->set(in.level);
  c.in[6]->set<std::int64_t>(kPeriodNs);
}

// ---- a loop over ARRAY[0..999] OF LREAL ----

const char* const kArraySt = R"(
FUNCTION_BLOCK Window
VAR_INPUT
  x : LREAL;
  gain, offset : LREAL;
END_VAR
VAR_OUTPUT
  sum, mean, peak : LREAL;
  peak_at : INT;
END_VAR
VAR
  buf : ARRAY[0..999] OF LREAL;
  head : INT;
END_VAR
VAR_TEMP
  i : INT;
  v : LREAL;
END_VAR
(* The newest sample over the oldest, then the window scaled: its sum, mean and peak. *)
buf[head] := x;
head := head + 1;
IF head >= 1000 THEN
  head := 0;
END_IF;
sum := 0.0;
peak := buf[0] * gain + offset;
peak_at := 0;
FOR i := 0 TO 999 DO
  v := buf[i] * gain + offset;
  sum := sum + v;
  IF v > peak THEN
    peak := v;
    peak_at := i;
  END_IF;
END_FOR;
mean := sum / 1000.0;
END_FUNCTION_BLOCK
)";

class WindowCpp final : public Block {
 public:
  enum Pin { kX, kGain, kOffset, kSum, kMean, kPeak, kPeakAt, kPins };
  void execute(ScanContext&) noexcept override {
    const double gain = in<double>(kGain), offset = in<double>(kOffset);
    buf_[head_] = in<double>(kX);
    head_ = static_cast<std::int16_t>(head_ + 1);
    if (head_ >= 1000) head_ = 0;
    double sum = 0.0;
    double peak = buf_[0] * gain + offset;
    std::int16_t peak_at = 0;
    for (std::int16_t i = 0; i <= 999; ++i) {
      const double v = buf_[i] * gain + offset;
      sum = sum + v;
      if (v > peak) {
        peak = v;
        peak_at = i;
      }
    }
    out<double>(kSum, sum);
    out<double>(kMean, sum / 1000.0);
    out<double>(kPeak, peak);
    out<std::int16_t>(kPeakAt, peak_at);
  }

 private:
  double buf_[1000] = {};
  std::int16_t head_ = 0;
};

struct WindowInput {
  double x, gain, offset;
};

std::vector<WindowInput> window_inputs() {
  std::mt19937_64 g(230023);
  std::normal_distribution<double> n(0, 1);
  std::vector<WindowInput> v(kInputSets);
  double x = 0;
  for (int k = 0; k < kInputSets; ++k) {
    x = 0.99 * x + n(g);
    v[k] = {x, 1.0 + 0.001 * (k % 7), 0.5 * (k % 3)};
  }
  return v;
}

struct WindowCells {
  Cell *x, *gain, *offset, *sum, *mean, *peak, *peak_at;
};
WindowCells window_cells(StBlock& b) {
  return {b.cell("x"), b.cell("gain"), b.cell("offset"), b.cell("sum"), b.cell("mean"), b.cell("peak"), b.cell("peak_at")};
}
WindowCells window_cells(PinCells<WindowCpp::kPins>& p) {
  Cell* c = p.cells;
  return {c + WindowCpp::kX,    c + WindowCpp::kGain, c + WindowCpp::kOffset, c + WindowCpp::kSum,
          c + WindowCpp::kMean, c + WindowCpp::kPeak, c + WindowCpp::kPeakAt};
}
inline void put(const WindowCells& c, const WindowInput& in) {
  c.x->set(in.x);
  c.gain->set(in.gain);
  c.offset->set(in.offset);
}

// ---- string handling on STRING[80] ----

const char* const kStringsSt = R"(
FUNCTION_BLOCK AlarmText
VAR_INPUT
  name : STRING[80];
  code : INT;
  count : DINT;
END_VAR
VAR_OUTPUT
  msg, head, detail : STRING[80];
  length, colon : INT;
END_VAR
msg := CONCAT('ALARM ', INT_TO_STRING(code), ' at ', name, ': count=', DINT_TO_STRING(count));
length := LEN(msg);
colon := FIND(msg, ': ');
head := LEFT(msg, colon - 1);
detail := MID(msg, length - colon - 1, colon + 2);
END_FUNCTION_BLOCK
)";

// STRING[80] as a pin spanning cells, in the ST layout (st_string.hpp: the
// length, then the characters, zeros after them), so that a string pin is
// bound to cells like any other.
constexpr int kString80Cells = vm::string_cells(80, false);

class AlarmTextCpp final : public Block {
 public:
  // Pin k's first cell; a string pin spans kString80Cells cells.
  static constexpr int kName = 0, kCode = kName + kString80Cells, kCount = kCode + 1, kMsg = kCount + 1,
                       kHead = kMsg + kString80Cells, kDetail = kHead + kString80Cells,
                       kLen = kDetail + kString80Cells, kColon = kLen + 1, kPins = kColon + 1;

  void execute(ScanContext&) noexcept override {
    // Fixed buffers, cut at 80 characters as STRING[80] is.
    struct Text {
      char c[81];
      int n = 0;
      void add(const char* s, int len) noexcept {
        const int k = std::min(len, 80 - n);
        std::memcpy(c + n, s, static_cast<std::size_t>(k));
        n += k;
      }
    };
    const Cell* name = pin_cell(kName);
    char num[24];
    Text msg;
    msg.add("ALARM ", 6);
    msg.add(num, static_cast<int>(std::to_chars(num, num + sizeof num, in<std::int16_t>(kCode)).ptr - num));
    msg.add(" at ", 4);
    msg.add(vm::str_chars(name), static_cast<int>(name[0].get<std::uint64_t>()));
    msg.add(": count=", 8);
    msg.add(num, static_cast<int>(std::to_chars(num, num + sizeof num, in<std::int32_t>(kCount)).ptr - num));
    // FIND(msg, ': '): 1-based, 0 when absent.
    int colon = 0;
    for (int k = 0; k + 1 < msg.n; ++k)
      if (msg.c[k] == ':' && msg.c[k + 1] == ' ') {
        colon = k + 1;
        break;
      }
    const int head = std::max(colon - 1, 0);
    const int detail_from = colon + 1, detail_n = std::max(msg.n - colon - 1, 0);
    write(pin_cell(kMsg), msg.c, msg.n);
    write(pin_cell(kHead), msg.c, head);
    write(pin_cell(kDetail), msg.c + detail_from, detail_n);
    out<std::int16_t>(kLen, static_cast<std::int16_t>(msg.n));
    out<std::int16_t>(kColon, static_cast<std::int16_t>(colon));
  }

 private:
  static void write(Cell* dst, const char* s, int n) noexcept {
    dst[0].set<std::uint64_t>(static_cast<std::uint64_t>(n));
    char* chars = reinterpret_cast<char*>(dst + 1);
    std::memcpy(chars, s, static_cast<std::size_t>(n));
    std::memset(chars + n, 0, static_cast<std::size_t>((kString80Cells - 1) * 8 - n));
  }
};

struct AlarmInput {
  const char* name;
  std::int16_t code;
  std::int32_t count;
};

std::vector<AlarmInput> alarm_inputs() {
  static const char* const names[] = {"pump 1", "conveyor B", "oven zone 3", "press", "filler head 12",
                                      "robot cell west", "cooling water", "M7"};
  std::mt19937_64 g(2300);
  std::uniform_int_distribution<int> name(0, 7), code(-32768, 32767);
  std::uniform_int_distribution<std::int32_t> count(-2'000'000'000, 2'000'000'000);
  std::vector<AlarmInput> v(kInputSets);
  for (int k = 0; k < kInputSets; ++k)
    v[k] = {names[name(g)], static_cast<std::int16_t>(code(g)), k % 5 == 0 ? count(g) : k};
  return v;
}

struct AlarmCells {
  Cell *name, *code, *count, *msg, *head, *detail, *len, *colon;
};
AlarmCells alarm_cells(StBlock& b) {
  return {b.cell("name"), b.cell("code"), b.cell("count"), b.cell("msg"),
          b.cell("head"), b.cell("detail"), b.cell("length"), b.cell("colon")};
}
AlarmCells alarm_cells(PinCells<AlarmTextCpp::kPins>& p) {
  Cell* c = p.cells;
  return {c + AlarmTextCpp::kName, c + AlarmTextCpp::kCode,   c + AlarmTextCpp::kCount,
          c + AlarmTextCpp::kMsg,  c + AlarmTextCpp::kHead,   c + AlarmTextCpp::kDetail,
          c + AlarmTextCpp::kLen,  c + AlarmTextCpp::kColon};
}
// The name's cells as the runtime copies a STRING[80] pin: all of them.
inline void put(const AlarmCells& c, const AlarmInput& in) {
  vm::str_set(c.name, 80, in.name, std::strlen(in.name));
  c.code->set(in.code);
  c.count->set(in.count);
}

// ---------------------------------------------------------------------------
// Fixtures: one instance per side, built once; the check before timing.

std::vector<PidInput>& pids() {
  static auto v = pid_inputs();
  return v;
}
std::vector<StationInput>& stations() {
  static auto v = station_inputs();
  return v;
}
std::vector<WindowInput>& windows() {
  static auto v = window_inputs();
  return v;
}
std::vector<AlarmInput>& alarms() {
  static auto v = alarm_inputs();
  return v;
}

ScanContext& context() {
  static NullSink sink;
  static ScanContext ctx = [] {
    ScanContext c;
    c.dt_ns = kPeriodNs;
    c.events = &sink;
    return c;
  }();
  return ctx;
}

// One timed loop: set the inputs, call the block as the task does.
template <class Inputs, class Cells>
void run(benchmark::State& state, Block& block, const Cells& cells, const Inputs& inputs) {
  ScanContext& ctx = context();
  std::size_t k = 0;
  for (auto _ : state) {
    put(cells, inputs[k & (kInputSets - 1)]);
    benchmark::ClobberMemory();
    execute_guarded(block, ctx);
    benchmark::ClobberMemory();
    ++k;
    ++ctx.scan;
    ctx.now_ns += kPeriodNs;
  }
}

// The instances (built at first use, after the check in main).
struct Instances {
  StBlock pass_st{kCallSt, "Pass"};
  PinCells<PassCpp::kPins> pass_pins;
  PassCpp pass_cpp;
  StBlock pid_st{kPidSt, "PidAw"};
  PinCells<PidCpp::kPins> pid_pins;
  PidCpp pid_cpp;
  StBlock station_st{kStateMachineSt, "Station"};
  PinCells<StationCpp::kPins> station_pins;
  StationCpp station_cpp;
  StBlock window_st{kArraySt, "Window"};
  PinCells<WindowCpp::kPins> window_pins;
  WindowCpp window_cpp;
  StBlock alarm_st{kStringsSt, "AlarmText"};
  PinCells<AlarmTextCpp::kPins> alarm_pins;
  AlarmTextCpp alarm_cpp;
  // The same ST on the interpreter alone (what runs where native code
  // cannot be made: not x86-64, or no executable memory).
  StBlock pass_interp{kCallSt, "Pass", vm::Engine::Interpreter};
  StBlock pid_interp{kPidSt, "PidAw", vm::Engine::Interpreter};
  StBlock station_interp{kStateMachineSt, "Station", vm::Engine::Interpreter};
  StBlock window_interp{kArraySt, "Window", vm::Engine::Interpreter};
  StBlock alarm_interp{kStringsSt, "AlarmText", vm::Engine::Interpreter};
  Instances() {
    pass_cpp.bind_pins(pass_pins.pins);
    pid_cpp.bind_pins(pid_pins.pins);
    station_cpp.bind_pins(station_pins.pins);
    window_cpp.bind_pins(window_pins.pins);
    // A string pin spans cells: its pin pointer is its first cell.
    alarm_cpp.bind_pins(alarm_pins.pins);
  }
};

Instances& instances() {
  static Instances i;
  return i;
}

void BM_Call_St(benchmark::State& s) { run(s, instances().pass_st, pass_cells(instances().pass_st), pass_inputs()); }
void BM_Call_Cpp(benchmark::State& s) { run(s, instances().pass_cpp, pass_cells(instances().pass_pins), pass_inputs()); }
void BM_Pid_St(benchmark::State& s) { run(s, instances().pid_st, pid_cells(instances().pid_st), pids()); }
void BM_Pid_Cpp(benchmark::State& s) { run(s, instances().pid_cpp, pid_cells(instances().pid_pins), pids()); }
void BM_StateMachine_St(benchmark::State& s) {
  run(s, instances().station_st, station_cells(instances().station_st), stations());
}
void BM_StateMachine_Cpp(benchmark::State& s) {
  run(s, instances().station_cpp, station_cells(instances().station_pins), stations());
}
void BM_ArrayLoop_St(benchmark::State& s) { run(s, instances().window_st, window_cells(instances().window_st), windows()); }
void BM_ArrayLoop_Cpp(benchmark::State& s) {
  run(s, instances().window_cpp, window_cells(instances().window_pins), windows());
}
void BM_Strings_St(benchmark::State& s) { run(s, instances().alarm_st, alarm_cells(instances().alarm_st), alarms()); }
void BM_Strings_Cpp(benchmark::State& s) { run(s, instances().alarm_cpp, alarm_cells(instances().alarm_pins), alarms()); }

void BM_Call_StInterp(benchmark::State& s) {
  run(s, instances().pass_interp, pass_cells(instances().pass_interp), pass_inputs());
}
void BM_Pid_StInterp(benchmark::State& s) { run(s, instances().pid_interp, pid_cells(instances().pid_interp), pids()); }
void BM_StateMachine_StInterp(benchmark::State& s) {
  run(s, instances().station_interp, station_cells(instances().station_interp), stations());
}
void BM_ArrayLoop_StInterp(benchmark::State& s) {
  run(s, instances().window_interp, window_cells(instances().window_interp), windows());
}
void BM_Strings_StInterp(benchmark::State& s) {
  run(s, instances().alarm_interp, alarm_cells(instances().alarm_interp), alarms());
}

BENCHMARK(BM_Call_St);
BENCHMARK(BM_Call_StInterp);
BENCHMARK(BM_Call_Cpp);
BENCHMARK(BM_Pid_St);
BENCHMARK(BM_Pid_StInterp);
BENCHMARK(BM_Pid_Cpp);
BENCHMARK(BM_StateMachine_St);
BENCHMARK(BM_StateMachine_StInterp);
BENCHMARK(BM_StateMachine_Cpp);
BENCHMARK(BM_ArrayLoop_St);
BENCHMARK(BM_ArrayLoop_StInterp);
BENCHMARK(BM_ArrayLoop_Cpp);
BENCHMARK(BM_Strings_St);
BENCHMARK(BM_Strings_StInterp);
BENCHMARK(BM_Strings_Cpp);

// Same inputs, same outputs, bit for bit, over kCheckScans scans of fresh
// instances. Returns the first difference, or "".
template <class Inputs, class Cells, class Outputs>
std::string compare(const char* what, Block& st, const Cells& st_cells, Block& cpp, const Cells& cpp_cells,
                    const Inputs& inputs, Outputs outputs) {
  ScanContext ctx;
  ctx.dt_ns = kPeriodNs;
  NullSink sink;
  ctx.events = &sink;
  for (int k = 0; k < kCheckScans; ++k) {
    put(st_cells, inputs[k & (kInputSets - 1)]);
    put(cpp_cells, inputs[k & (kInputSets - 1)]);
    execute_guarded(st, ctx);
    execute_guarded(cpp, ctx);
    for (const auto& [name, a, b, n] : outputs(st_cells, cpp_cells))
      for (int c = 0; c < n; ++c)
        if (a[c].raw != b[c].raw)
          return std::string(what) + ": scan " + std::to_string(k) + ": " + name + " differs (ST " +
                 std::to_string(a[c].raw) + ", C++ " + std::to_string(b[c].raw) + ", cell " + std::to_string(c) + ")";
    ++ctx.scan;
    ctx.now_ns += kPeriodNs;
  }
  if (sink.events) return std::string(what) + ": " + std::to_string(sink.events) + " fault events";
  return "";
}

struct Out {
  const char* name;
  const Cell* a;
  const Cell* b;
  int n;
};

std::string check_equal_of(Instances& fresh, bool interp);

// Both engines against C++.
std::string check_equal() {
  Instances for_native, for_interp;  // each with C++ blocks from their start
  std::string e = check_equal_of(for_native, false);
  if (!e.empty()) return "native code: " + e;
  e = check_equal_of(for_interp, true);
  return e.empty() ? e : "interpreter: " + e;
}

std::string check_equal_of(Instances& fresh, bool interp) {
  StBlock& pass_st = interp ? fresh.pass_interp : fresh.pass_st;
  StBlock& pid_st = interp ? fresh.pid_interp : fresh.pid_st;
  StBlock& station_st = interp ? fresh.station_interp : fresh.station_st;
  StBlock& window_st = interp ? fresh.window_interp : fresh.window_st;
  StBlock& alarm_st = interp ? fresh.alarm_interp : fresh.alarm_st;
  std::string e;
  e = compare("call", pass_st, pass_cells(pass_st), fresh.pass_cpp, pass_cells(fresh.pass_pins),
              pass_inputs(), [](const PassCells& a, const PassCells& b) { return std::vector<Out>{{"y", a.y, b.y, 1}}; });
  if (!e.empty()) return e;
  e = compare("PID", pid_st, pid_cells(pid_st), fresh.pid_cpp, pid_cells(fresh.pid_pins), pids(),
              [](const PidCells& a, const PidCells& b) {
                return std::vector<Out>{{"out", a.out, b.out, 1}, {"saturated", a.saturated, b.saturated, 1}};
              });
  if (!e.empty()) return e;
  e = compare("state machine", station_st, station_cells(station_st), fresh.station_cpp,
              station_cells(fresh.station_pins), stations(), [](const StationCells& a, const StationCells& b) {
                std::vector<Out> v;
                for (int k = 0; k < 8; ++k) v.push_back({kStationOutputs[k], a.out[k], b.out[k], 1});
                return v;
              });
  if (!e.empty()) return e;
  e = compare("array loop", window_st, window_cells(window_st), fresh.window_cpp,
              window_cells(fresh.window_pins), windows(), [](const WindowCells& a, const WindowCells& b) {
                return std::vector<Out>{{"sum", a.sum, b.sum, 1},
                                        {"mean", a.mean, b.mean, 1},
                                        {"peak", a.peak, b.peak, 1},
                                        {"peak_at", a.peak_at, b.peak_at, 1}};
              });
  if (!e.empty()) return e;
  e = compare("strings", alarm_st, alarm_cells(alarm_st), fresh.alarm_cpp, alarm_cells(fresh.alarm_pins),
              alarms(), [](const AlarmCells& a, const AlarmCells& b) {
                return std::vector<Out>{{"msg", a.msg, b.msg, kString80Cells},
                                        {"head", a.head, b.head, kString80Cells},
                                        {"detail", a.detail, b.detail, kString80Cells},
                                        {"length", a.len, b.len, 1},
                                        {"colon", a.colon, b.colon, 1}};
              });
  return e;
}

// ---------------------------------------------------------------------------
// Loading a 10,000-line source: function blocks with declarations, a
// function each, expressions, IF, CASE, FOR, an array and a built-in timer,
// and a program every ten blocks that instances and calls them.

std::string station_source(int k) {
  std::string s;
  s += "FUNCTION Scale_" + std::to_string(k) + " : LREAL\n";
  s += "VAR_INPUT\n  raw : INT;\n  lo, hi : LREAL;\nEND_VAR\n";
  s += "Scale_" + std::to_string(k) + " := lo + (hi - lo) * INT_TO_LREAL(raw) / 27648.0;\n";
  s += "END_FUNCTION\n\n";
  s += "(* Tank station " + std::to_string(k) + ": level, a valve sequence, a running error sum. *)\n";
  s += "FUNCTION_BLOCK Tank_" + std::to_string(k) + "\n";
  s += "VAR_INPUT\n  enable : BOOL;\n  raw_level : INT;\n  setpoint : LREAL := " + std::to_string(k % 90 + 5) +
       ".5;\n  cmd : INT;\nEND_VAR\n";
  s += "VAR_OUTPUT\n  level : LREAL;\n  valve : BOOL;\n  alarm : BOOL;\n  state : INT;\n  total : DINT;\nEND_VAR\n";
  s += "VAR\n  history : ARRAY[0..15] OF LREAL;\n  idx : INT;\n  delay : TON;\n  err_sum : LREAL;\n  i : INT;\n"
       "END_VAR\n";
  s += "level := Scale_" + std::to_string(k) + "(raw := raw_level, lo := 0.0, hi := 100.0);\n";
  s += "history[idx] := level;\nidx := (idx + 1) MOD 16;\nerr_sum := 0.0;\n";
  s += "FOR i := 0 TO 15 DO\n  err_sum := err_sum + ABS(history[i] - setpoint);\nEND_FOR;\n";
  s += "delay(IN := enable AND level > setpoint, PT := T#" + std::to_string(100 + k % 900) + "ms);\n";
  s += "CASE state OF\n";
  s += "  0:\n    IF enable THEN state := 1; END_IF;\n";
  s += "  1:\n    valve := TRUE;\n    IF delay.Q THEN state := 2; END_IF;\n";
  s += "  2:\n    valve := FALSE;\n    IF err_sum > 100.0 THEN\n      state := 3;\n    ELSIF cmd = 2 THEN\n"
       "      state := 0;\n    END_IF;\n";
  s += "  3:\n    alarm := TRUE;\n    IF NOT enable THEN\n      alarm := FALSE;\n      state := 0;\n    END_IF;\n";
  s += "ELSE\n  state := 0;\nEND_CASE;\n";
  s += "IF valve AND (level < setpoint - 5.0 OR cmd = 1) THEN\n  total := total + 1;\n"
       "ELSIF NOT valve AND total > 1000 THEN\n  total := 0;\nEND_IF;\n";
  s += "END_FUNCTION_BLOCK\n\n";
  return s;
}

std::string line_source(int first, int n) {
  const std::string m = std::to_string(first / n);
  std::string s = "PROGRAM Line_" + m + "\nVAR\n";
  for (int k = first; k < first + n; ++k) s += "  t" + std::to_string(k) + " : Tank_" + std::to_string(k) + ";\n";
  s += "  raw : ARRAY[0..9] OF INT;\n  run : BOOL := TRUE;\n  alarms : INT;\n  j : INT;\nEND_VAR\n";
  s += "FOR j := 0 TO 9 DO\n  raw[j] := (raw[j] + 97 * (j + 1)) MOD 27648;\nEND_FOR;\nalarms := 0;\n";
  for (int k = first; k < first + n; ++k) {
    const std::string t = "t" + std::to_string(k);
    s += t + "(enable := run, raw_level := raw[" + std::to_string(k - first) + "], cmd := alarms MOD 3);\n";
    s += "IF " + t + ".alarm THEN alarms := alarms + 1; END_IF;\n";
  }
  s += "run := alarms < 5;\nEND_PROGRAM\n\n";
  return s;
}

std::string source_10k(int* lines) {
  std::string s = "(* Generated for bench_st_vs_cpp: loading 10,000 lines (docs/benchmarks.md section 17). *)\n";
  for (int k = 0;; k += 10) {
    for (int j = k; j < k + 10; ++j) s += station_source(j);
    s += line_source(k, 10);
    const int n = static_cast<int>(std::count(s.begin(), s.end(), '\n'));
    if (n >= 10'000) {
      *lines = n;
      return s;
    }
  }
}

void BM_Load10k(benchmark::State& state) {
  int lines = 0;
  const std::string source = source_10k(&lines);
  using Clock = std::chrono::steady_clock;
  double parse_s = 0, check_s = 0, compile_s = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    st::ParseResult parsed = st::parse(source, SourceFile("gen.st"));
    const auto t1 = Clock::now();
    st::CheckedProgram checked = st::check({&parsed.unit}, vm::block_signatures(builtin_blocks()));
    const auto t2 = Clock::now();
    st::StDiagnostics diags;
    auto module = vm::compile(checked, &builtin_blocks(), diags);
    const auto t3 = Clock::now();
    if (!parsed.ok() || !checked.ok() || !module || !diags.list().empty()) {
      state.SkipWithError("the generated source does not compile");
      return;
    }
    benchmark::DoNotOptimize(module);
    parse_s += std::chrono::duration<double>(t1 - t0).count();
    check_s += std::chrono::duration<double>(t2 - t1).count();
    compile_s += std::chrono::duration<double>(t3 - t2).count();
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["lines"] = lines;
  state.counters["parse_ms"] = parse_s / n * 1e3;
  state.counters["check_ms"] = check_s / n * 1e3;
  state.counters["compile_ms"] = compile_s / n * 1e3;
  state.counters["total_ms"] = (parse_s + check_s + compile_s) / n * 1e3;
}
BENCHMARK(BM_Load10k)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  try {
    // --listing: the compiled code of the four ST blocks, then exit.
    for (int k = 1; k < argc; ++k)
      if (std::strcmp(argv[k], "--listing") == 0) {
        Instances& i = instances();
        std::fputs(i.pid_st.listing().c_str(), stdout);
        std::fputs(i.station_st.listing().c_str(), stdout);
        std::fputs(i.window_st.listing().c_str(), stdout);
        std::fputs(i.alarm_st.listing().c_str(), stdout);
        return 0;
      }
    const std::string e = check_equal();
    if (!e.empty()) {
      std::fprintf(stderr, "ST and C++ differ: %s\n", e.c_str());
      return 1;
    }
    std::fprintf(stderr, "ST (native code and interpreter) and C++ agree on %d scans of each case\n", kCheckScans);
    instances();
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "%s\n", ex.what());
    return 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
