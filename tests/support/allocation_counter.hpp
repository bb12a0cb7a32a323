// Counts the binary's operator new calls while `counting_allocations` is set:
// the scan-path tests' proof that a scan allocates nothing. Linking
// syncplc_allocation_counter (tests/CMakeLists.txt) into a test executable
// replaces its global operator new and delete (allocation_counter.cpp) —
// only there, since the replacement is pulled in by a use of these counters.
#pragma once

#include <atomic>

namespace syncplc::test {

extern std::atomic<bool> counting_allocations;
extern std::atomic<long> allocations_counted;

}  // namespace syncplc::test
