// libFuzzer harness on compiled Structured Text's two engines: any bytes
// as a source; when it parses, checks and compiles (against the real
// built-in blocks), every PROGRAM and FUNCTION_BLOCK that needs nothing
// bound from outside (no VAR_IN_OUT, no VAR_EXTERNAL) runs three scans as
// native code and on the interpreter, and the two must agree: the same
// result of each scan (the loop budget), the same fault events in the same
// order, and the same bits in every variable (docs/st.md, "How compiled ST
// runs": a NaN from two NaNs is the one freedom). Under ASan and UBSan the
// interpreter's handlers, and step() that native code calls them through,
// are watched too. On machines without native code both runs are the
// interpreter and the harness checks that it is deterministic.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fblocks/library.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"
#include "runtime/st/vm/block_signatures.hpp"
#include "runtime/st/vm/codegen.hpp"
#include "runtime/st/vm/instance.hpp"
#include "runtime/st/vm/same_cell.hpp"
#include "runtime/st/vm/vm.hpp"

namespace {

using namespace syncplc;
using st::vm::same_cell;

void check(bool ok) {
  if (!ok) std::abort();
}

class Faults final : public EventSink {
 public:
  void push(const Event& e) noexcept override {
    if (texts.size() < 64) texts.emplace_back(e.message);
  }
  std::vector<std::string> texts;
};

struct Side {
  std::unique_ptr<st::vm::Instance> instance;
  Faults faults;
  ScanContext ctx;
};

// The cells that hold values (not an address: references, embedded blocks).
std::vector<std::pair<std::uint32_t, std::uint32_t>> value_cells(const st::vm::CompiledPou& pou, bool* bound) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  *bound = false;
  for (const st::vm::VarSlot& v : pou.vars) {
    const auto scope = static_cast<st::VarScope>(v.scope);
    if (scope == st::VarScope::InOut || scope == st::VarScope::External) *bound = true;
    const st::Type* t = v.type;
    while (t && t->kind == st::Type::Kind::Array && t->element) t = t->element;
    if (!t || t->kind == st::Type::Kind::FunctionBlock || t->kind == st::Type::Kind::Struct) continue;
    out.emplace_back(v.at, v.cells);
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const st::ParseResult parsed = st::parse(text, SourceFile("fuzz.st"));
  if (!parsed.ok()) return 0;
  const st::CheckedProgram checked = st::check({&parsed.unit}, st::vm::block_signatures(builtin_blocks()));
  if (!checked.ok()) return 0;
  st::StDiagnostics d1, d2;
  std::shared_ptr<st::vm::Module> native = st::vm::compile(checked, &builtin_blocks(), d1);
  std::shared_ptr<st::vm::Module> interp = st::vm::compile(checked, &builtin_blocks(), d2);
  check((native == nullptr) == (interp == nullptr));
  if (!native) return 0;
  st::vm::set_engine(*interp, st::vm::Engine::Interpreter);
  int runs = 0;
  for (std::uint32_t p = 0; p < native->pous.size() && runs < 4; ++p) {
    const st::vm::CompiledPou& pou = native->pous[p];
    if (pou.kind == st::PouKind::Function) continue;
    bool bound = false;
    const auto cells = value_cells(pou, &bound);
    if (bound) continue;
    ++runs;
    Side a, b;
    try {
      a.instance = std::make_unique<st::vm::Instance>(native, p, st::vm::InstanceSetup{"f", 10'000'000, 1});
      b.instance = std::make_unique<st::vm::Instance>(interp, p, st::vm::InstanceSetup{"f", 10'000'000, 1});
    } catch (const std::exception&) {
      continue;  // a built-in block the parameters cannot make: the loader reports it
    }
    for (Side* s : {&a, &b}) {
      s->ctx.dt_ns = 10'000'000;
      s->ctx.events = &s->faults;
    }
    for (int scan = 0; scan < 3; ++scan) {
      // A small budget: a runaway loop costs little, and the budget's stop
      // is compared too.
      const bool ra = a.instance->scan(a.ctx, 5'000), rb = b.instance->scan(b.ctx, 5'000);
      check(ra == rb);
      for (const auto& [at, n] : cells)
        for (std::uint32_t k = 0; k < n; ++k)
          check(same_cell(a.instance->frame()[at + k].raw, b.instance->frame()[at + k].raw));
      check(a.faults.texts == b.faults.texts);
      for (Side* s : {&a, &b}) {
        ++s->ctx.scan;
        s->ctx.now_ns += s->ctx.dt_ns;
      }
    }
  }
  return 0;
}
