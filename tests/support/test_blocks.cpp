#include "tests/support/test_blocks.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace syncplc::testing {
namespace {

class Record final : public Block {
 public:
  explicit Record(std::string name) : name_(std::move(name)) {}
  void execute(ScanContext& ctx) override {
    double v = in<double>(0);
    records().push_back({name_, ctx.task, ctx.now_ns, ctx.dt_ns, ctx.scan, v});
    out<double>(1, v);
  }

 private:
  std::string name_;
};

class Hook final : public Block {
 public:
  void execute(ScanContext& ctx) override {
    if (hook()) hook()(ctx);
    out<double>(1, in<double>(0));
  }
};

class Stamp final : public Block {
 public:
  void execute(ScanContext& ctx) override {
    double v = static_cast<double>(ctx.now_ns) / 1e6;
    for (int i = 0; i < 4; ++i) out<double>(i, v);
  }
};

PinDecl in_pin(const char* n) { return PinDecl{n, PinDir::In, TypeClass::Exact, IecType::LREAL, "", false, "", "", ""}; }
PinDecl out_pin(const char* n) { return PinDecl{n, PinDir::Out, TypeClass::Exact, IecType::LREAL, "", false, "", "", ""}; }

}  // namespace

std::vector<ScanRecord>& records() {
  static std::vector<ScanRecord> r;
  return r;
}

std::function<void(ScanContext&)>& hook() {
  static std::function<void(ScanContext&)> h;
  return h;
}

const BlockRegistry& test_blocks() {
  static const BlockRegistry reg = [] {
    BlockRegistry r;
    register_iec_blocks(r);
    r.add(BlockTypeInfo{"RECORD", "test", "records every scan", "", {in_pin("IN"), out_pin("OUT")}, {}, std::nullopt, false,
                        [](BlockSetup& s) { return std::make_unique<Record>(s.instance_name()); }});
    r.add(BlockTypeInfo{"HOOK", "test", "calls the test's hook", "", {in_pin("IN"), out_pin("OUT")}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Hook>(); }});
    r.add(BlockTypeInfo{"STAMP", "test", "four copies of the scan time in ms", "",
                        {out_pin("A"), out_pin("B"), out_pin("C"), out_pin("D")}, {}, std::nullopt, false,
                        [](BlockSetup&) { return std::make_unique<Stamp>(); }});
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
