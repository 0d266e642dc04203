// The first checks of every read-in-place blob view (tables, model sets, feature, view and
// aspect databases) before its header is read: data present, aligned for its records, and long
// enough for the header. Each refusal names the blob.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh {

inline Status CheckBlobStart(const void* blob, size_t size, size_t alignment, size_t header_size,
                             const char* what) {
  if (blob == nullptr) return Status::Error(StatusCode::kInvalidArgument, "%s: no data", what);
  if (reinterpret_cast<uintptr_t>(blob) % alignment != 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: memory not %zu-byte aligned", what,
                         alignment);
  }
  if (size < header_size) {
    return Status::Error(StatusCode::kDataLoss,
                         "%s truncated: %zu bytes, the header alone needs %zu", what, size,
                         header_size);
  }
  return Status::Ok();
}

// Reserved header bytes: zero in every blob written, so that a later version can give them a
// meaning and a flipped bit in them is refused.
inline bool AllZero(const void* data, size_t n) {
  const auto* p = static_cast<const uint8_t*>(data);
  for (size_t i = 0; i < n; ++i) {
    if (p[i] != 0) return false;
  }
  return true;
}

}  // namespace sh
