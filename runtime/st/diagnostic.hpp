// An error or a note of the Structured Text front end at its place in the
// source: "file:line:col: message", as the project loader's errors read.
#pragma once

#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"

namespace syncplc::st {

struct StDiagnostic {
  enum class Severity { Error, Note };
  Severity severity = Severity::Error;
  SourceLoc loc;
  std::string message;
  // "file:line:col: message" (an error) or "file:line:col: note: message".
  std::string text() const {
    return loc.text() + (severity == Severity::Note ? ": note: " : ": ") + message;
  }
};

// Collects the diagnostics of one source in the order found, the lexer's and
// the parser's together.
class StDiagnostics {
 public:
  void error(const SourceLoc& loc, std::string message) {
    list_.push_back({StDiagnostic::Severity::Error, loc, std::move(message)});
  }
  void note(const SourceLoc& loc, std::string message) {
    list_.push_back({StDiagnostic::Severity::Note, loc, std::move(message)});
  }
  bool has_errors() const;
  std::size_t error_count() const;
  // Sorted by line and column (stable for equal places), as one source's diagnostics are shown.
  std::vector<StDiagnostic> sorted() const;
  const std::vector<StDiagnostic>& list() const { return list_; }

 private:
  std::vector<StDiagnostic> list_;
};

// The candidate closest to `name` (case-insensitive, at most a third of its
// letters wrong), or "" when none is close: the suggestion for a misspelt name.
std::string closest_name(std::string_view name, const std::vector<std::string_view>& candidates);

}  // namespace syncplc::st
