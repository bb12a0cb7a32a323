// The type checker against the corpus: all valid programs (tests/st/corpus/
// valid) check together without an error; each file of type_errors/ gives
// exactly the lines of its .errors file (SYNCPLC_ST_UPDATE=1 rewrites them).
#include <algorithm>

#include "tests/st/checker_fixture.hpp"
#include "tests/st/corpus_files.hpp"

namespace syncplc::st {
namespace {

using corpus::check_against;
using corpus::read;
using corpus::sources;

TEST(StCheckCorpus, ValidProgramsCheckTogetherWithoutErrors) {
  std::vector<std::unique_ptr<ParseResult>> parsed;
  std::vector<const CompilationUnit*> units;
  for (const auto& f : sources("valid")) {
    parsed.push_back(std::make_unique<ParseResult>(parse(read(f), SourceFile(f.filename().string()))));
    ASSERT_TRUE(parsed.back()->ok()) << f;
    units.push_back(&parsed.back()->unit);
  }
  ASSERT_GE(units.size(), 15u);
  const CheckedProgram p = check(units, testing::builtin_blocks());
  for (const auto& d : p.diagnostics.list()) ADD_FAILURE() << d.text();
  EXPECT_NE(p.pou("FillSequence"), nullptr);
}

TEST(StCheckCorpus, TypeErrorsGiveTheirErrors) {
  const auto files = sources("type_errors");
  EXPECT_GE(files.size(), 3u);
  for (const auto& f : files) {
    SCOPED_TRACE(f.filename().string());
    ParseResult r = parse(read(f), SourceFile(f.filename().string()));
    ASSERT_TRUE(r.ok()) << r.diagnostics.list()[0].text();
    const CheckedProgram p = check({&r.unit}, testing::builtin_blocks());
    EXPECT_FALSE(p.ok());
    std::string lines;
    for (const auto& d : p.diagnostics.sorted()) lines += d.text() + "\n";
    check_against(f, ".errors", lines);
  }
}

// The checker also runs over what the parser recovered from broken sources
// (absent parts are ExprKind::None): no crash, every error inside the file.
TEST(StCheckCorpus, RecoveredTreesOfInvalidProgramsCheckSafely) {
  for (const auto& f : sources("invalid")) {
    SCOPED_TRACE(f.filename().string());
    const std::string text = read(f);
    ParseResult r = parse(text, SourceFile(f.filename().string()));
    const CheckedProgram p = check({&r.unit}, testing::builtin_blocks());
    const int lines = static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1;
    for (const auto& d : p.diagnostics.list()) {
      EXPECT_GE(d.loc.line, 1) << d.text();
      EXPECT_LE(d.loc.line, lines) << d.text();
    }
  }
}

}  // namespace
}  // namespace syncplc::st
