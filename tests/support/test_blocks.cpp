#include "tests/support/test_blocks.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "runtime/core/pin_decl.hpp"

namespace syncplc::testing {
namespace {

class Record final : public Block {
 public:
  explicit Record(std::string name) : name_(std::move(name)) {}
  void execute(ScanContext& ctx) noexcept override {
    double v = in<double>(0);
    records().push_back({name_, ctx.task, ctx.now_ns, ctx.dt_ns, ctx.scan, v});
    out<double>(1, v);
  }

 private:
  std::string name_;
};

class Hook final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    if (hook()) hook()(ctx);
    out<double>(1, in<double>(0));
  }
};

class Hang final : public Block {
 public:
  void execute(ScanContext&) noexcept override {
    while (hang_armed().load(std::memory_order_acquire) && !hang_release().load(std::memory_order_acquire)) {
    }
    out<double>(1, in<double>(0));
  }
};

class Stamp final : public Block {
 public:
  void execute(ScanContext& ctx) noexcept override {
    double v = static_cast<double>(ctx.now_ns) / 1e6;
    for (int i = 0; i < 4; ++i) out<double>(i, v);
  }
};

// OUT[i] := GAIN * IN[i] (i = 1..N); SUM := sum of IN; FLAGS[i] := IN[i] > 0.
class ArrayGain final : public Block {
 public:
  explicit ArrayGain(BlockSetup& s) : n_(s.pin_length(0)), gain_(s.param<double>("GAIN")) {
    if (s.pin_length(1) != n_) s.error("pin lengths disagree");
  }
  void execute(ScanContext&) noexcept override {
    double sum = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      double v = in<double>(0, i);
      out<double>(1, i, gain_ * v);
      out<bool>(3, i, v > 0);
      sum += v;
    }
    out<double>(2, sum);
  }

 private:
  std::uint32_t n_;
  double gain_;
};

// SUM := SUM + K * IN each scan (state for online-change tests); K tunable,
// MODE structural.
class Accumulate final : public Block {
 public:
  explicit Accumulate(BlockSetup& s) : k_(s.param<double>("K")) {}
  void execute(ScanContext&) noexcept override {
    sum_ += k_ * in<double>(0);
    out<double>(1, sum_);
  }
  void retune_from(const Block& fresh) noexcept override { k_ = static_cast<const Accumulate&>(fresh).k_; }

 private:
  double k_;
  double sum_ = 0;
};

PinDecl in_pin(const char* n) { return input(n, IecType::LREAL); }
PinDecl out_pin(const char* n) { return output(n, IecType::LREAL); }

}  // namespace

std::vector<ScanRecord>& records() {
  static std::vector<ScanRecord> r;
  return r;
}

std::function<void(ScanContext&)>& hook() {
  static std::function<void(ScanContext&)> h;
  return h;
}

std::atomic<bool>& hang_armed() {
  static std::atomic<bool> a{false};
  return a;
}

std::atomic<bool>& hang_release() {
  static std::atomic<bool> r{false};
  return r;
}

const BlockRegistry& test_blocks() {
  static const BlockRegistry reg = [] {
    BlockRegistry r;
    register_iec_blocks(r);
    register_motion_blocks(r);
    r.add(BlockTypeInfo{"RECORD", "test", "records every scan", "", {in_pin("IN"), out_pin("OUT")}, {}, std::nullopt, false,
                        [](BlockSetup& s) { return std::make_unique<Record>(s.instance_name()); }});
    r.add(BlockTypeInfo{"HOOK", "test", "calls the test's hook", "", {in_pin("IN"), out_pin("OUT")}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Hook>(); }});
    r.add(BlockTypeInfo{"HANG", "test", "a scan that does not end once armed", "", {in_pin("IN"), out_pin("OUT")}, {},
                        std::nullopt, false, [](BlockSetup&) { return std::make_unique<Hang>(); }});
    r.add(BlockTypeInfo{"STAMP", "test", "four copies of the scan time in ms", "",
                        {out_pin("A"), out_pin("B"), out_pin("C"), out_pin("D")}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Stamp>(); }});
    PinDecl ain = in_pin("IN"), aout = out_pin("OUT"), flags = out_pin("FLAGS");
    ain.length_param = aout.length_param = flags.length_param = "N";
    ain.unit = aout.unit = "m";
    flags.type = IecType::BOOL;
    ParamDecl n{"N", IecType::INT, "3", 0, 5000, "", "elements"};
    ParamDecl gain{"GAIN", IecType::LREAL, "2", std::nullopt, std::nullopt, "", "gain"};
    r.add(BlockTypeInfo{"ARRAY_GAIN", "test", "OUT[i] := GAIN*IN[i]; SUM := sum of IN", "",
                        {ain, aout, out_pin("SUM"), flags}, {n, gain}, std::nullopt, false,
                        [](BlockSetup& s) { return std::make_unique<ArrayGain>(s); }});
    ParamDecl k{"K", IecType::LREAL, "1", std::nullopt, std::nullopt, "", "gain (tunable)"};
    k.tunable = true;
    ParamDecl mode{"MODE", IecType::INT, "0", std::nullopt, std::nullopt, "", "structure"};
    r.add(BlockTypeInfo{"ACC", "test", "SUM := SUM + K*IN", "", {in_pin("IN"), out_pin("SUM")}, {k, mode}, std::nullopt,
                        false, [](BlockSetup& s) { return std::make_unique<Accumulate>(s); }});
    ParamDecl cap{"N", IecType::DINT, "100000", 1, 10000000, "", "samples kept"};
    r.add(BlockTypeInfo{"LOG", "test", "keeps (now, IN) of its first N scans", "", {in_pin("IN"), out_pin("OUT")}, {cap},
                        std::nullopt, false, [](BlockSetup& s) {
                          return std::make_unique<LogBlock>(static_cast<std::size_t>(s.param<std::int32_t>("N")));
                        }});
    return r;
  }();
  return reg;
}

std::string write_temp_file(const std::string& name, const std::string& text) {
  auto dir = std::filesystem::temp_directory_path() / ("syncplc-test-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  auto p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace syncplc::testing
