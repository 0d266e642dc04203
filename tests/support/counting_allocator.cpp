// Replaces the global allocation functions (one definition per program, hence a library of its
// own, linked only into the no-allocation tests).
#include "tests/support/counting_allocator.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<uint64_t> g_allocations{0};

void* Allocate(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
}  // namespace

namespace sh::testing {
uint64_t HeapAllocations() { return g_allocations.load(); }
}  // namespace sh::testing

void* operator new(std::size_t n) {
  if (void* p = Allocate(n)) return p;
  std::abort();  // out of memory in a test: nothing sensible to continue with
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return Allocate(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return Allocate(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
