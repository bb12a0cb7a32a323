// libFuzzer harness on the Structured Text front end (runtime/st): any bytes
// as a source file through the lexer, the parser, the AST dump and the type
// checker (st::check, with a few built-in blocks as the loader gives them,
// one with array pins sized by a parameter).
// The checker runs on every tree, also one with syntax errors: the parser's
// recovery leaves partial declarations and expressions, and the checker must
// take those too. Besides ASan/UBSan (and the stack: the nesting limit must
// hold for the checker's walk as for the parser's), it checks that every
// diagnostic lies inside the file (line 1 … lines + 1, column >= 1), that a
// source with errors says so, and that parsing and checking are
// deterministic (the same dump and the same diagnostics twice).
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "runtime/st/ast_dump.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

void check_inside(const syncplc::st::StDiagnostics& diagnostics, int lines) {
  for (const auto& d : diagnostics.list()) {
    check(d.loc.line >= 1 && d.loc.line <= lines + 1);
    check(d.loc.col >= 1);
    check(!d.message.empty());
  }
}

// Built-in blocks with inputs, outputs and a TIME pin, as the BlockRegistry
// gives them to the loader.
const std::vector<syncplc::st::BlockSignature>& blocks() {
  static const std::vector<syncplc::st::BlockSignature> b = {
      {"TON", {{"IN", false, "BOOL"}, {"PT", false, "TIME"}, {"Q", true, "BOOL"}, {"ET", true, "TIME"}}, ""},
      {"R_TRIG", {{"CLK", false, "BOOL"}, {"Q", true, "BOOL"}}, ""},
      {"CTU",
       {{"CU", false, "BOOL"}, {"R", false, "BOOL"}, {"PV", false, "INT"}, {"Q", true, "BOOL"}, {"CV", true, "INT"}},
       ""},
      // Array pins of the length a parameter gives, a required parameter
      // and one with a default and a range (TRANSIENT_SYNC's shape): the
      // declaration's parameters, `s : SYNC := (n := 3)`.
      {"SYNC",
       {{"r", false, "LREAL", "n", 1024}, {"x", true, "LREAL", "n", 1024}, {"done", true, "BOOL"}},
       "",
       {{"n", "DINT", std::nullopt, 1.0, 1024.0, ""},
        {"t_f", "LREAL", syncplc::st::ConstValue{true, 0, 0.5}, 0.0, 100.0, "s"}}},
  };
  return b;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace syncplc;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  int lines = 1;
  for (char c : text) lines += c == '\n';
  const st::ParseResult r = st::parse(text, SourceFile("fuzz.st"));
  check_inside(r.diagnostics, lines);
  const std::string dumped = st::dump(r.unit);
  const st::ParseResult again = st::parse(text, SourceFile("fuzz.st"));
  check(st::dump(again.unit) == dumped);
  check(again.diagnostics.list().size() == r.diagnostics.list().size());

  const st::CheckedProgram checked = st::check({&r.unit}, blocks());
  check_inside(checked.diagnostics, lines);
  const st::CheckedProgram checked_again = st::check({&again.unit}, blocks());
  check(checked_again.diagnostics.list().size() == checked.diagnostics.list().size());
  for (std::size_t i = 0; i < checked.diagnostics.list().size(); ++i)
    check(checked_again.diagnostics.list()[i].text() == checked.diagnostics.list()[i].text());
  return 0;
}
