// Helpers of the VM's tests: compile ST sources (parse, check, generate)
// against the real built-in blocks, make an instance of one POU and run it
// scan by scan in virtual time, reading and writing its variables by path.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"
#include "runtime/st/vm/block_signatures.hpp"
#include "runtime/st/vm/codegen.hpp"
#include "runtime/st/vm/instance.hpp"
#include "runtime/st/vm/var_path.hpp"
#include "runtime/st/vm/vm.hpp"

namespace syncplc::st::testing {

class CountingSink final : public EventSink {
 public:
  void push(const Event& e) noexcept override { events.push_back(e); }
  std::vector<Event> events;
};

struct StRun {
  std::vector<std::unique_ptr<ParseResult>> parsed;
  CheckedProgram checked;
  StDiagnostics codegen;
  std::shared_ptr<const vm::Module> module;
  std::unique_ptr<vm::Instance> instance;
  CountingSink sink;
  ScanContext ctx;
  std::int64_t budget = 1'000'000;
  std::vector<std::string> errors;

  // Compiles `sources` and instances POU `pou`; errors (of any stage) in `errors`.
  StRun(const std::vector<std::string>& sources, const std::string& pou, std::int64_t period_ns = 10'000'000,
        vm::Engine engine = vm::Engine::Native) {
    std::vector<const CompilationUnit*> units;
    for (std::size_t i = 0; i < sources.size(); ++i) {
      parsed.push_back(std::make_unique<ParseResult>(parse(sources[i], SourceFile("t" + std::to_string(i) + ".st"))));
      for (const auto& d : parsed.back()->diagnostics.list())
        if (d.severity == StDiagnostic::Severity::Error) errors.push_back(d.text());
      units.push_back(&parsed.back()->unit);
    }
    if (!errors.empty()) return;
    checked = check(units, vm::block_signatures(::syncplc::builtin_blocks()));
    for (const auto& d : checked.diagnostics.sorted())
      if (d.severity == StDiagnostic::Severity::Error) errors.push_back(d.text());
    if (!errors.empty()) return;
    auto m = vm::compile(checked, &::syncplc::builtin_blocks(), codegen);
    for (const auto& d : codegen.list()) errors.push_back(d.text());
    if (!m) return;
    vm::set_engine(*m, engine);
    module = std::move(m);
    const int p = module->find(pou);
    if (p < 0) {
      errors.push_back("no POU " + pou);
      return;
    }
    instance = std::make_unique<vm::Instance>(module, static_cast<std::uint32_t>(p),
                                              vm::InstanceSetup{"main", period_ns, 1});
    ctx.dt_ns = period_ns;
    ctx.events = &sink;
  }

  bool ok() const { return errors.empty() && instance; }

  // Runs n scans; false when the loop budget stopped one.
  bool scan(int n = 1) {
    bool all = true;
    for (int k = 0; k < n; ++k) {
      all = instance->scan(ctx, budget) && all;
      ++ctx.scan;
      ctx.now_ns += ctx.dt_ns;
    }
    return all;
  }

  Cell* cell(const std::string& path) {
    std::string why;
    const auto r = vm::resolve_path(*module, static_cast<std::uint32_t>(module->find(instance->pou().name)), path, &why);
    EXPECT_TRUE(r) << why;
    if (!r) return nullptr;
    Cell* c = instance->frame() + r->at;
    return r->reference ? reinterpret_cast<Cell*>(static_cast<std::uintptr_t>(c->raw)) : c;
  }
  template <class T>
  T get(const std::string& path) {
    Cell* c = cell(path);
    return c ? c->get<T>() : T{};
  }
  template <class T>
  void set(const std::string& path, T v) {
    if (Cell* c = cell(path)) c->set<T>(v);
  }
  std::string str(const std::string& path) {
    Cell* c = cell(path);
    if (!c) return "";
    return std::string(reinterpret_cast<const char*>(c + 1), c->get<std::uint64_t>());
  }
  std::vector<std::string> fault_texts() const {
    std::vector<std::string> out;
    for (const Event& e : sink.events)
      if (e.kind == EventKind::BlockFault) out.push_back(e.message);
    return out;
  }
};

// A PROGRAM Main with `vars` and `body`: its body starts on line 5.
inline std::unique_ptr<StRun> run_program(const std::string& vars, const std::string& body,
                                          const std::string& before = "") {
  auto r = std::make_unique<StRun>(
      std::vector<std::string>{(before.empty() ? "" : before + "\n") + "PROGRAM Main\nVAR\n" + vars + "\nEND_VAR\n" +
                               body + "\nEND_PROGRAM\n"},
      "Main");
  EXPECT_TRUE(r->errors.empty()) << r->errors[0];
  return r;
}

}  // namespace syncplc::st::testing
