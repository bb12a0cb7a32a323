// The VM's string instruction: one StringCall (code.hpp) on a frame, through
// the fixed-capacity string functions of st_string.hpp.
#pragma once

#include "runtime/st/vm/vm.hpp"

namespace syncplc::st::vm {

void string_op(Vm& vm, Cell* frame, const StringCall& call) noexcept;

}  // namespace syncplc::st::vm
