// The code generator: a CheckedProgram (the type checker's result) in, a
// Module (code.hpp) out. Runs at load, after a check without errors; what it
// cannot compile (a construct the checker lets through that the VM has no
// form for) is an error at its file:line:col in `diagnostics`.
#pragma once

#include <memory>

#include "runtime/core/block.hpp"
#include "runtime/st/checker.hpp"
#include "runtime/st/vm/code.hpp"

namespace syncplc::st::vm {

// `blocks` gives the built-in FB types the program instances (their pins'
// order and cells); null when the sources use none.
std::unique_ptr<Module> compile(const CheckedProgram& program, const BlockRegistry* blocks,
                                StDiagnostics& diagnostics);

}  // namespace syncplc::st::vm
