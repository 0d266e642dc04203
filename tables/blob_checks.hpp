// The checks every read-in-place blob view shares (tables, model sets, feature, view and aspect
// databases): data present, aligned for its records and long enough for the header; the header
// every stereohash blob starts with (magic, format version, header size, total size) and the
// whole blob's CRC-32 it carries right after them; and the placement of each section the header
// points to. Each refusal names the blob.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "blobs are read in place: little-endian");

// The common start of every stereohash blob header: magic (8 bytes), u16 format version, 2 bytes
// of the kind's own, u32 header size, u64 total size, then the u32 CRC-32 of the whole blob
// with that field read as zero (the blob's identity, as `tables info` prints it).
inline constexpr size_t kBlobFormatVersionOffset = 8;
inline constexpr size_t kBlobHeaderSizeOffset = 12;
inline constexpr size_t kBlobTotalSizeOffset = 16;
inline constexpr size_t kBlobCrc32Offset = 24;

// Every section of every blob starts at a multiple of this many bytes from the blob's start.
inline constexpr size_t kSectionAlignment = 64;

inline constexpr size_t AlignSection(size_t n) {
  return (n + kSectionAlignment - 1) / kSectionAlignment * kSectionAlignment;
}

// Where a header says a section lies.
struct SectionRef {
  uint64_t offset;  // from the start of the blob
  uint64_t size;    // bytes
};
static_assert(sizeof(SectionRef) == 16);

// What a reader expects of its blob's common header.
struct BlobFormat {
  const char* what;    // names the blob in messages: "table blob", "aspect table"
  const char* magic;   // 8 bytes
  uint16_t version;    // the one format version this build reads
  size_t header_size;  // sizeof the kind's header
  size_t alignment;    // of `blob` in memory, for the kind's records
};

// CheckBlobStart, then magic, version, header size and total size (== `size`), in that order.
Status CheckBlobPrefix(const void* blob, size_t size, const BlobFormat& format);
// The whole blob's CRC-32 against the one its header carries; `blob` holds the header prefix.
Status CheckBlobCrc32(const void* blob, size_t size, const char* what);
// Both: a blob whose common header and CRC-32 hold, ready for the kind's own checks.
inline Status CheckBlobHeader(const void* blob, size_t size, const BlobFormat& format) {
  SH_RETURN_IF_ERROR(CheckBlobPrefix(blob, size, format));
  return CheckBlobCrc32(blob, size, format.what);
}

// A section inside a blob of `total` bytes, at a multiple of kSectionAlignment, holding exactly
// `count` elements of `element_size` bytes. `blob` names the blob and `name` the section in
// the refusal ("aspect table corrupt: basis section has 40 bytes, expected 48").
Status CheckSection(const SectionRef& section, uint64_t count, size_t element_size, uint64_t total,
                    const char* blob, const char* name);

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
