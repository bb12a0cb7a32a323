// Errors found while loading a project, each with its place in the file.
#pragma once

#include <string>
#include <vector>

#include "runtime/core/config_node.hpp"

namespace syncplc {

struct Diagnostic {
  SourceLoc loc;
  std::string message;
  std::string text() const { return loc.text() + ": " + message; }
};

class Diagnostics {
 public:
  void error(const SourceLoc& loc, std::string message) { list_.push_back({loc, std::move(message)}); }
  bool empty() const { return list_.empty(); }
  // Puts context in front of an error already recorded (e.g. "trace: ").
  void prefix_message(std::size_t index, const std::string& prefix) { list_.at(index).message.insert(0, prefix); }
  std::size_t size() const { return list_.size(); }
  // Sorted by file, line, column (stable for equal places).
  std::vector<Diagnostic> sorted() const;
  const std::vector<Diagnostic>& list() const { return list_; }

 private:
  std::vector<Diagnostic> list_;
};

}  // namespace syncplc
