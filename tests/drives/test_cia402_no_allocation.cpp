// CIA402_DRIVE on the scan path never allocates: a project with two
// instances (SINT and INT mode pins) is run in virtual time with the drive's
// objects set to every state, a fault with its events, a reset, a mode change
// and the following error window, counting every operator new of this binary.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "fblocks/library.hpp"
#include "runtime/core/virtual_clock.hpp"
#include "runtime/project/loader.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// GCC sees free() of what it takes for operator new's memory; here both are malloc's.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The nothrow forms too (std::stable_sort's temporary buffer in the scan-test
// runner of this binary uses them): every form this binary's delete frees
// must come from malloc, or AddressSanitizer reports a mismatch.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace syncplc {
namespace {

TEST(Cia402ScanPath, DoesNotAllocate) {
  LoadOptions lo;
  lo.blocks = &builtin_blocks();
  auto r = load_project_text(R"(
tasks:
  - {name: servo, period: 1ms, priority: 80}
tags:
  - {name: enable, type: BOOL}
  - {name: reset, type: BOOL}
  - {name: statusword, type: UINT}
  - {name: display, type: SINT}
  - {name: mode, type: SINT}
  - {name: display16, type: INT}
  - {name: mode16, type: INT}
  - {name: x_set, type: LREAL}
  - {name: actual, type: DINT}
  - {name: error_code, type: UINT}
blocks:
  - {name: a1, type: CIA402_DRIVE, params: {transition_timeout: 0.005, following_error_window: 1, following_error_time: 0.002}}
  - {name: a2, type: CIA402_DRIVE, params: {idle_state: 2}}
connections:
  - enable -> a1.enable
  - reset -> a1.reset
  - statusword -> a1.statusword
  - display -> a1.modes_display
  - mode -> a1.mode
  - x_set -> a1.position_set
  - actual -> a1.position_actual
  - error_code -> a1.error_code
  - enable -> a2.enable
  - statusword -> a2.statusword
  - display16 -> a2.modes_display
  - mode16 -> a2.mode
)", "cia402_alloc.yaml", lo);
  for (const auto& d : r.diagnostics.list()) ADD_FAILURE() << d.text();
  ASSERT_TRUE(r.program);
  Program& p = *r.program;
  auto cell = [&](const char* name) -> Cell& { return *p.live_cell(*p.resolve(name)); };
  VirtualClock clock(p);
  clock.run_until(5'000'000);  // warm up, uncounted
  cell("enable").set<bool>(true);
  cell("mode").set<std::int8_t>(8);
  cell("display").set<std::int8_t>(8);
  cell("mode16").set<std::int16_t>(9);
  cell("display16").set<std::int16_t>(9);
  std::int64_t t = 5'000'000;
  long allocations = 0;
  auto window = [&](std::uint16_t sw) {
    cell("statusword").set<std::uint16_t>(sw);
    g_allocations = 0;
    g_counting = true;
    t += 10'000'000;
    clock.run_until(t);
    g_counting = false;
    allocations += g_allocations.load();
  };
  for (std::uint16_t sw : {0x0000, 0x0240, 0x0221, 0x0233, 0x0237, 0x0207, 0x0241}) window(sw);
  cell("x_set").set<double>(5.0);  // outside the window: event
  window(0x0237);
  cell("error_code").set<std::uint16_t>(0x7300);
  window(0x020F);  // fault reaction: event
  window(0x0208);
  cell("reset").set<bool>(true);
  window(0x0208);  // reset refused: timeout event
  window(0x0240);  // recovered: event
  cell("mode").set<std::int8_t>(3);
  window(0x0237);  // mode not displayed: timeout
  EXPECT_EQ(allocations, 0);
  EXPECT_GT(p.tasks[0]->stats.summary().scans, 100u);
}

}  // namespace
}  // namespace syncplc
