// Large objects on the heap whose untouched pages stay out of resident memory.
//
// std::make_unique<T>() value-initialises, and for a class without a user-provided constructor
// that zero-fills the whole object: every page of a pipeline sized for the largest image is
// written, so all of it becomes resident even when the frame uses a fraction (docs/memory.md).
// MakeZeroed takes the storage from calloc, which is zero by contract and which, for large
// blocks, hands out fresh kernel pages without writing them; T is then default-initialised
// (constructors and member initialisers only), so the bytes nobody initialises read as zero,
// exactly as after make_unique, but each page becomes resident only when first used.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>

namespace sh {

template <typename T>
struct ZeroedDeleter {
  void operator()(T* object) const {
    object->~T();
    std::free(object);
  }
};

template <typename T>
using ZeroedPtr = std::unique_ptr<T, ZeroedDeleter<T>>;

// Null when the allocation fails.
template <typename T>
ZeroedPtr<T> MakeZeroed() {
  static_assert(alignof(T) <= alignof(std::max_align_t), "calloc's alignment is too small for T");
  void* storage = std::calloc(1, sizeof(T));
  if (storage == nullptr) return nullptr;
  return ZeroedPtr<T>(new (storage) T);  // default-initialisation keeps calloc's zeros
}

}  // namespace sh
