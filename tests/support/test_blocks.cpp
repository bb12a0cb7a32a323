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
    const Pin in = input("IN", IecType::LREAL), out = output("OUT", IecType::LREAL);
    r.add(BlockTypeInfo{"RECORD", "test", "records every scan", "", {in, out}, {}, std::nullopt, false,
                        [](BlockSetup& s) { return std::make_unique<Record>(s.instance_name()); }});
    r.add(BlockTypeInfo{"HOOK", "test", "calls the test's hook", "", {in, out}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Hook>(); }});
    r.add(BlockTypeInfo{"HANG", "test", "a scan that does not end once armed", "", {in, out}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Hang>(); }});
    r.add(BlockTypeInfo{"STAMP", "test", "four copies of the scan time in ms", "",
                        {output("A", IecType::LREAL), output("B", IecType::LREAL), output("C", IecType::LREAL),
                         output("D", IecType::LREAL)},
                        {}, std::nullopt, false, [](BlockSetup&) { return std::make_unique<Stamp>(); }});
    r.add(BlockTypeInfo{"ARRAY_GAIN", "test", "OUT[i] := GAIN*IN[i]; SUM := sum of IN", "",
                        {input("IN", IecType::LREAL).unit("m").array("N"),
                         output("OUT", IecType::LREAL).unit("m").array("N"), output("SUM", IecType::LREAL),
                         output("FLAGS", IecType::BOOL).array("N")},
                        {parameter("N", IecType::INT).init("3").min(0).max(5000).doc("elements"),
                         parameter("GAIN", IecType::LREAL).init("2").doc("gain")},
                        std::nullopt, false, [](BlockSetup& s) { return std::make_unique<ArrayGain>(s); }});
    r.add(BlockTypeInfo{"ACC", "test", "SUM := SUM + K*IN", "", {in, output("SUM", IecType::LREAL)},
                        {parameter("K", IecType::LREAL).init("1").tunable().doc("gain (tunable)"),
                         parameter("MODE", IecType::INT).init("0").doc("structure")},
                        std::nullopt, false, [](BlockSetup& s) { return std::make_unique<Accumulate>(s); }});
    r.add(BlockTypeInfo{"LOG", "test", "keeps (now, IN) of its first N scans", "", {in, out},
                        {parameter("N", IecType::DINT).init("100000").min(1).max(10000000).doc("samples kept")},
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
