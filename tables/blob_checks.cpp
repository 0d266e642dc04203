#include "tables/blob_checks.hpp"

#include <cstring>

#include "recog/base/crc32.hpp"

namespace sh {
namespace {

template <typename T>
T FieldAt(const void* blob, size_t offset) {
  T v;
  std::memcpy(&v, static_cast<const uint8_t*>(blob) + offset, sizeof(v));
  return v;
}

}  // namespace

Status CheckBlobPrefix(const void* blob, size_t size, const BlobFormat& format) {
  SH_RETURN_IF_ERROR(CheckBlobStart(blob, size, format.alignment, format.header_size, format.what));
  if (std::memcmp(blob, format.magic, 8) != 0) {
    return Status::Error(StatusCode::kInvalidArgument, "not a stereohash %s (bad magic number)",
                         format.what);
  }
  const auto version = FieldAt<uint16_t>(blob, kBlobFormatVersionOffset);
  if (version != format.version) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "%s format version %u, this build reads version %u", format.what, version,
                         format.version);
  }
  const auto header_size = FieldAt<uint32_t>(blob, kBlobHeaderSizeOffset);
  if (header_size != format.header_size) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: header size field is %u", format.what,
                         header_size);
  }
  const auto total_size = FieldAt<uint64_t>(blob, kBlobTotalSizeOffset);
  if (total_size != size) {
    return Status::Error(StatusCode::kDataLoss,
                         "%s truncated or padded: header says %llu bytes, got %zu", format.what,
                         static_cast<unsigned long long>(total_size), size);
  }
  return Status::Ok();
}

Status CheckBlobCrc32(const void* blob, size_t size, const char* what) {
  const auto carried = FieldAt<uint32_t>(blob, kBlobCrc32Offset);
  const uint32_t crc = BlobCrc32(blob, size, kBlobCrc32Offset);
  if (crc != carried) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: CRC-32 %08x, header says %08x", what,
                         crc, carried);
  }
  return Status::Ok();
}

Status CheckSection(const SectionRef& section, uint64_t count, size_t element_size, uint64_t total,
                    const char* blob, const char* name) {
  if (section.offset % kSectionAlignment != 0) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: %s section misaligned", blob, name);
  }
  if (section.offset > total || section.size > total - section.offset) {
    return Status::Error(StatusCode::kDataLoss, "%s truncated: %s section ends past the blob", blob,
                         name);
  }
  // Counts stay below 2^48 and records are a few KiB: the product cannot wrap.
  const uint64_t expected = count * uint64_t{element_size};
  if (section.size != expected) {
    return Status::Error(
        StatusCode::kDataLoss, "%s corrupt: %s section has %llu bytes, expected %llu", blob, name,
        static_cast<unsigned long long>(section.size), static_cast<unsigned long long>(expected));
  }
  return Status::Ok();
}

}  // namespace sh
