// A deterministic text form of the AST (S-expressions, one statement or
// declaration a line, each with its @line:col) for tests and debugging.
#pragma once

#include <string>

#include "runtime/st/ast.hpp"

namespace syncplc::st {

std::string dump(const CompilationUnit& unit);
std::string dump(const Expr& expr);
std::string dump(const TypeSpec& type);
// A statement list, each statement on its lines, indented by `indent` spaces.
std::string dump(const std::vector<Statement>& statements, int indent = 0);

}  // namespace syncplc::st
