// One block of memory taken at initialisation and carved into the buffers of a workspace, sized
// for the configured image rather than the compile-time maximum (docs/memory.md).
//
// The block comes from calloc: zero by contract, and for large blocks fresh kernel pages that
// become resident as they are first written (or all at once under mlockall). Nothing is taken
// per frame: a workspace carves its buffers once, in its Init.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>

namespace sh {

class InitBlock {
 public:
  // Alignment of every piece (a cache line; SIMD loads of float rows stay aligned).
  static constexpr size_t kAlign = 64;

  // Bytes to reserve for `count` objects of T, with the alignment slack of one piece.
  template <typename T>
  static constexpr size_t PieceBytes(size_t count) {
    return count * sizeof(T) + kAlign;
  }

  // Frees the previous block (its pieces become invalid) and takes `bytes` zeroed bytes; false
  // when calloc fails.
  bool Allocate(size_t bytes) {
    data_.reset();
    bytes_ = used_ = 0;
    data_.reset(static_cast<uint8_t*>(std::calloc(bytes > 0 ? bytes : 1, 1)));
    if (data_ == nullptr) return false;
    bytes_ = bytes;
    return true;
  }

  // The next `count` objects of T, aligned to kAlign; null when the block is too small (the
  // caller reserved PieceBytes<T>(count) per piece, so this means a sizing error).
  template <typename T>
  T* Take(size_t count) {
    return CarvePiece<T>(data_.get(), bytes_, &used_, count);
  }

  // The next `count` objects of T from `data` (`bytes` long, `*used` of it taken), aligned to
  // kAlign; null when it is too small. For blocks another owner lends as well as for this one.
  template <typename T>
  static T* CarvePiece(uint8_t* data, size_t bytes, size_t* used, size_t count) {
    static_assert(alignof(T) <= kAlign, "piece alignment too small for T");
    if (data == nullptr) return nullptr;
    const uintptr_t at = reinterpret_cast<uintptr_t>(data) + *used;
    const size_t start = *used + (kAlign - at % kAlign) % kAlign;
    if (start > bytes || count > (bytes - start) / sizeof(T)) return nullptr;
    *used = start + count * sizeof(T);
    return reinterpret_cast<T*>(data + start);
  }

  size_t bytes() const { return bytes_; }
  // The start of the block (null before Allocate), for memory another stage borrows whole.
  uint8_t* data() const { return data_.get(); }

 private:
  struct Free {
    void operator()(uint8_t* p) const { std::free(p); }
  };
  std::unique_ptr<uint8_t, Free> data_;
  size_t bytes_ = 0, used_ = 0;
};

}  // namespace sh
