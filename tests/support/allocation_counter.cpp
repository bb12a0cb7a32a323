// The replaced global operator new/delete of allocation_counter.hpp.
#include "tests/support/allocation_counter.hpp"

#include <cstdlib>
#include <new>

namespace syncplc::test {
std::atomic<bool> counting_allocations{false};
std::atomic<long> allocations_counted{0};
}  // namespace syncplc::test

namespace {
void count_one() {
  if (syncplc::test::counting_allocations.load(std::memory_order_relaxed))
    syncplc::test::allocations_counted.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

// GCC sees free() of what it takes for operator new's memory; here both are malloc's.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) {
  count_one();
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// The nothrow forms too (std::stable_sort's temporary buffer takes one and
// gives it back through the sized delete above): every new and delete of the
// binary pairs malloc with free, as ASan checks.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  count_one();
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
