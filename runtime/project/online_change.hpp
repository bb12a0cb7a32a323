// Replacing a running program by a newly loaded one (`syncplc run` reloads its
// project file on SIGHUP). The new program is loaded and checked completely
// before anything stops; a project that fails to load changes nothing. The
// swap happens at scan boundaries: every task finishes its current scan, the
// old drivers close, the new ones open, and the tasks start on a new epoch.
// Tag values survive the swap (a warm start for tags, as an online change in
// CODESYS keeps variables); block instances start fresh.
#pragma once

#include <cstddef>

#include "runtime/core/program.hpp"

namespace syncplc {

// Copies the current (published) value of every tag of `from` that exists in
// `to` with the same name, type and size into `to`'s image and snapshots.
// Call before `to` starts running. Returns how many tags were carried over.
std::size_t carry_over_tags(const Program& from, Program& to);

}  // namespace syncplc
