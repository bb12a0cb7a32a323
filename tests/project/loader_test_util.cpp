#include "tests/project/loader_test_util.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "runtime/core/pin_decl.hpp"

namespace syncplc::loadertest {
namespace {

class Gain final : public Block {
 public:
  explicit Gain(BlockSetup& s) : k_(s.param<double>("K")), n_(s.param<std::int32_t>("N")) {}
  void execute(ScanContext&) noexcept override { out<double>(1, in<double>(0) * k_); }
  double k() const { return k_; }
  std::int32_t n() const { return n_; }

 private:
  double k_;
  std::int32_t n_;
};

class Pass final : public Block {
 public:
  void execute(ScanContext&) noexcept override { out<double>(1, in<double>(0)); }
};


}  // namespace

const BlockRegistry& param_blocks() {
  static const BlockRegistry reg = [] {
    BlockRegistry r;
    register_iec_blocks(r);
    BlockTypeInfo g;
    g.name = "GAIN";
    g.category = "test";
    g.doc = "OUT := IN * K";
    g.pins = {input("IN", IecType::LREAL).required(), output("OUT", IecType::LREAL)};
    g.params = {parameter("K", IecType::LREAL).init("1").min(0).max(100).unit("m/s"),
                parameter("N", IecType::DINT).init("0")};
    g.create = [](BlockSetup& s) -> std::unique_ptr<Block> { return std::make_unique<Gain>(s); };
    r.add(std::move(g));
    BlockTypeInfo nd;
    nd.name = "NEED";
    nd.category = "test";
    nd.doc = "OUT := IN; needs P";
    nd.pins = {input("IN", IecType::LREAL), output("OUT", IecType::LREAL)};
    nd.params = {parameter("P", IecType::INT)};
    nd.create = [](BlockSetup&) -> std::unique_ptr<Block> { return std::make_unique<Pass>(); };
    r.add(std::move(nd));
    return r;
  }();
  return reg;
}

double gain_k(const Program& p, const std::string& instance) {
  auto it = p.instances.find(instance);
  if (it == p.instances.end()) return -1;
  const auto& bi = p.tasks[it->second.first]->blocks[it->second.second];
  const auto* g = dynamic_cast<const Gain*>(bi.block.get());
  return g ? g->k() : -1;
}

std::filesystem::path temp_dir() {
  return std::filesystem::temp_directory_path() / ("syncplc-loader-test-" + std::to_string(getpid()));
}

std::string temp_file(const std::string& name, const std::string& text) {
  static const bool cleanup = [] {
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(temp_dir(), ec);
    });
    return true;
  }();
  (void)cleanup;
  auto dir = temp_dir();
  std::filesystem::create_directories(dir);
  auto path = dir / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::trunc) << text;
  return path.string();
}

std::string temp_root() { return temp_dir().string() + "/"; }

}  // namespace syncplc::loadertest
