// The parser against a corpus of ST sources (tests/st/corpus): every valid
// program parses without a diagnostic and dumps to its .expected file (the
// dump is also stable from one parse to the next); every invalid one gives
// exactly the lines of its .errors file. Regenerate the expected files after
// an intended change with SYNCPLC_ST_UPDATE=1 and review the diff.
#include <gtest/gtest.h>

#include "runtime/st/ast_dump.hpp"
#include "runtime/st/parser.hpp"
#include "tests/st/corpus_files.hpp"

namespace syncplc::st {
namespace {

using corpus::check_against;
using corpus::read;
using corpus::sources;

TEST(StCorpus, ValidProgramsParseAndDumpAsExpected) {
  const auto files = sources("valid");
  EXPECT_GE(files.size(), 15u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    const std::string text = read(f);
    ParseResult r = parse(text, SourceFile(f.filename().string()));
    for (const auto& d : r.diagnostics.list())
      if (d.severity == StDiagnostic::Severity::Error) ADD_FAILURE() << d.text();  // notes (pragmas) are fine
    ASSERT_FALSE(r.unit.pous.empty() && r.unit.types.empty());
    const std::string dumped = dump(r.unit);
    EXPECT_EQ(dumped, dump(parse(text, SourceFile(f.filename().string())).unit)) << "dump not stable";
    check_against(f, ".expected", dumped);
  }
}

TEST(StCorpus, InvalidProgramsGiveTheirErrors) {
  const auto files = sources("invalid");
  EXPECT_GE(files.size(), 8u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    ParseResult r = parse(read(f), SourceFile(f.filename().string()));
    EXPECT_FALSE(r.ok());
    std::string lines;
    for (const auto& d : r.diagnostics.sorted()) lines += d.text() + "\n";
    check_against(f, ".errors", lines);
  }
}

}  // namespace
}  // namespace syncplc::st
