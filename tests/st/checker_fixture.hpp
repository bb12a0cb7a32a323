// Helpers of the type checker's tests: parse sources, check them together
// with the built-in blocks the corpus uses, and read the errors.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "runtime/st/checker.hpp"
#include "runtime/st/parser.hpp"

namespace syncplc::st::testing {

// A few built-in blocks as the loader will give them from the BlockRegistry
// (CTU and CTD at their INT instantiation).
inline std::vector<BlockSignature> builtin_blocks() {
  auto block = [](std::string name, std::vector<BlockSignature::PinSpec> pins) {
    return BlockSignature{std::move(name), std::move(pins), ""};
  };
  return {
      block("TON", {{"IN", false, "BOOL"}, {"PT", false, "TIME"}, {"Q", true, "BOOL"}, {"ET", true, "TIME"}}),
      block("TOF", {{"IN", false, "BOOL"}, {"PT", false, "TIME"}, {"Q", true, "BOOL"}, {"ET", true, "TIME"}}),
      block("TP", {{"IN", false, "BOOL"}, {"PT", false, "TIME"}, {"Q", true, "BOOL"}, {"ET", true, "TIME"}}),
      block("R_TRIG", {{"CLK", false, "BOOL"}, {"Q", true, "BOOL"}}),
      block("F_TRIG", {{"CLK", false, "BOOL"}, {"Q", true, "BOOL"}}),
      block("CTU", {{"CU", false, "BOOL"}, {"R", false, "BOOL"}, {"PV", false, "INT"}, {"Q", true, "BOOL"},
                    {"CV", true, "INT"}}),
      block("CTD", {{"CD", false, "BOOL"}, {"LD", false, "BOOL"}, {"PV", false, "INT"}, {"Q", true, "BOOL"},
                    {"CV", true, "INT"}}),
      block("NONLINEAR_FILTER", {{"r", false, "LREAL"}, {"r_dot", false, "LREAL"}, {"v_min", false, "LREAL"},
                                 {"v_max", false, "LREAL"}, {"a_min", false, "LREAL"}, {"a_max", false, "LREAL"},
                                 {"x", true, "LREAL"}, {"x_dot", true, "LREAL"}}),
  };
}

struct Checked {
  std::vector<std::unique_ptr<ParseResult>> parsed;  // kept alive: the checked program points into them
  CheckedProgram program;
  std::vector<std::string> parse_errors;

  // The checker's errors as "line:col: message" (the file name left out).
  std::vector<std::string> errors() const {
    std::vector<std::string> out;
    for (const auto& d : program.diagnostics.sorted())
      if (d.severity == StDiagnostic::Severity::Error)
        out.push_back(std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " + d.message);
    return out;
  }
  bool has(const std::string& part) const {
    for (const auto& e : errors())
      if (e.find(part) != std::string::npos) return true;
    return false;
  }
};

inline std::unique_ptr<Checked> check_sources(const std::vector<std::string>& sources) {
  auto c = std::make_unique<Checked>();
  std::vector<const CompilationUnit*> units;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    c->parsed.push_back(std::make_unique<ParseResult>(parse(sources[i], SourceFile("t" + std::to_string(i) + ".st"))));
    for (const auto& d : c->parsed.back()->diagnostics.list())
      if (d.severity == StDiagnostic::Severity::Error) c->parse_errors.push_back(d.text());
    units.push_back(&c->parsed.back()->unit);
  }
  c->program = check(units, builtin_blocks());
  return c;
}

inline std::unique_ptr<Checked> check_source(const std::string& source) {
  auto c = check_sources({source});
  EXPECT_TRUE(c->parse_errors.empty()) << c->parse_errors[0];
  return c;
}

// A PROGRAM with `vars` declared and `body` as its statements.
inline std::unique_ptr<Checked> check_program(const std::string& vars, const std::string& body,
                                              const std::string& before = "") {
  // Without `before`, the body starts on line 5.
  return check_source((before.empty() ? "" : before + "\n") + "PROGRAM P\nVAR\n" + vars + "\nEND_VAR\n" + body +
                      "\nEND_PROGRAM\n");
}

}  // namespace syncplc::st::testing
