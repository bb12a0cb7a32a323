// libFuzzer harness on the Structured Text front end (runtime/st): any bytes
// as a source file through the lexer, the parser and the AST dump. Besides
// ASan/UBSan (and the stack: the nesting limit must hold), it checks that
// every diagnostic lies inside the file (line 1 … lines + 1, column >= 1),
// that a source with errors says so, and that parsing is deterministic (the
// same dump and the same diagnostics twice).
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "runtime/st/ast_dump.hpp"
#include "runtime/st/parser.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace syncplc;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  int lines = 1;
  for (char c : text) lines += c == '\n';
  const st::ParseResult r = st::parse(text, SourceFile("fuzz.st"));
  for (const auto& d : r.diagnostics.list()) {
    check(d.loc.line >= 1 && d.loc.line <= lines + 1);
    check(d.loc.col >= 1);
    check(!d.message.empty());
  }
  const std::string dumped = st::dump(r.unit);
  const st::ParseResult again = st::parse(text, SourceFile("fuzz.st"));
  check(st::dump(again.unit) == dumped);
  check(again.diagnostics.list().size() == r.diagnostics.list().size());
  return 0;
}
