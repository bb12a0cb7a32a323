// What an online change did, in words: per task (kept, re-timed, added,
// removed, restarted), per block instance (kept, retuned, new, removed) and
// per driver (kept open, restarted, new, removed), per force (kept on the
// same element, or dropped and why). The change itself is
// runtime/core/program_change.hpp; `syncplc run` and `syncplc reload` print
// this, and it goes into the event list.
#pragma once

#include <string>
#include <vector>

#include "runtime/core/program_change.hpp"

namespace syncplc {

// One line: "reloaded: 12 kept, 1 retuned, 2 new, 0 removed; tasks: 2 kept, 1 added".
std::string change_summary(const ProgramChange& c);
// Every task, instance, driver and force with its fate, one per line, tasks first.
std::vector<std::string> change_report(const ProgramChange& c);

}  // namespace syncplc
