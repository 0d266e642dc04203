// Counts every operator new of the test binary that links stereohash_counting_allocator, to
// prove that a code path does not touch the heap: take HeapAllocations() before and after.
#pragma once

#include <cstdint>

namespace sh::testing {

// Allocations (all forms of operator new, throwing or not) since the program started.
uint64_t HeapAllocations();

}  // namespace sh::testing
