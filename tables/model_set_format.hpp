// The model-set blob: one file (or one linked-in array) holding every kind of model data the
// recognition paths use, each kind as a typed section. A section's payload is the blob of that
// kind byte for byte (hash tables, feature database, view database, aspect table), so each keeps
// its own validating view; the container adds a directory and the outer checks.
//
// Layout (all little-endian):
//
//   ModelSetHeader                    64 bytes, at offset 0
//   ModelSetSection[section_count]    the directory, right after the header
//   payloads                          each at a multiple of kModelSetAlignment, in any order,
//                                     not overlapping; gaps are zero padding
//
// The header's CRC-32 covers the whole blob with the CRC field read as zero; each directory
// entry also carries the CRC-32 of its payload. See docs/tables.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "tables/blob_checks.hpp"

namespace sh {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "blobs are read in place: little-endian");

inline constexpr char kModelSetMagic[8] = {'S', 'H', 'M', 'O', 'D', 'S', 'E', 'T'};
inline constexpr uint16_t kModelSetFormatVersion = 1;
inline constexpr size_t kModelSetAlignment = 64;
// More sections than kinds leaves room for kinds added later; a reader refuses more.
inline constexpr uint32_t kMaxModelSetSections = 16;

// Section kinds. The numbers are part of the format: never reuse one. A reader skips kinds it
// does not know (an older build reading a newer set) and refuses a kind given twice.
enum class SectionKind : uint32_t {
  kHash3d = 1,           // 3-D hash tables, SHTABLE (tables/table_format.hpp)
  kTextureFeatures = 2,  // printed models' feature database, SHTEXDB (tables/feature_db_format.hpp)
  kShapeViews = 3,       // colour parts' view database, SHVIEWS (recog/shape/view_database.hpp)
  kAspects2d = 4,        // one-camera aspect table, SHASPECT (tables/aspect_format.hpp)
};

struct ModelSetHeader {
  char magic[8];            // kModelSetMagic
  uint16_t format_version;  // kModelSetFormatVersion
  uint16_t reserved0;       // zero
  uint32_t header_size;     // sizeof(ModelSetHeader)
  uint64_t total_size;      // whole blob in bytes
  uint32_t blob_crc32;      // CRC-32 of bytes [0, total_size) with this field read as zero
  uint32_t section_count;   // 1..kMaxModelSetSections directory entries
  uint32_t entry_size;      // sizeof(ModelSetSection)
  uint8_t reserved1[28];    // zero
};
static_assert(sizeof(ModelSetHeader) == 64, "header layout is part of the format");
static_assert(std::is_standard_layout_v<ModelSetHeader>);

struct ModelSetSection {
  uint32_t kind;          // SectionKind
  uint16_t kind_version;  // the payload's own format version (its header says the same)
  uint16_t reserved0;     // zero
  uint64_t offset;        // from the start of the blob, a multiple of kModelSetAlignment
  uint64_t size;          // payload bytes (the section blob's own total size)
  uint32_t crc32;         // CRC-32 of the payload
  uint32_t reserved1;     // zero
};
static_assert(sizeof(ModelSetSection) == 32, "directory layout is part of the format");

// Every section payload is a stereohash blob that starts with this common prefix (magic,
// format version, header size, total size); the container checks it against the directory.
struct SectionBlobPrefix {
  char magic[8];
  uint16_t format_version;
  uint16_t reserved;  // differs by kind
  uint32_t header_size;
  uint64_t total_size;
};
static_assert(sizeof(SectionBlobPrefix) == 24);
// Right after the prefix every stereohash header (the model set's too) holds its blob_crc32: the
// CRC-32 of the whole blob, the blob's identity (BlobHeaderCrc32). Each format asserts it.
static_assert(sizeof(SectionBlobPrefix) == kBlobCrc32Offset);
static_assert(offsetof(ModelSetHeader, blob_crc32) == kBlobCrc32Offset);

// What the container knows of each kind: its name for messages and the magic of its payload.
struct SectionKindInfo {
  SectionKind kind;
  const char* name;
  char magic[8];
};
inline constexpr SectionKindInfo kSectionKinds[] = {
    {SectionKind::kHash3d, "HASH3D", {'S', 'H', 'T', 'A', 'B', 'L', 'E', '\0'}},
    {SectionKind::kTextureFeatures, "TEXTURE_FEATURES", {'S', 'H', 'T', 'E', 'X', 'D', 'B', '\0'}},
    {SectionKind::kShapeViews, "SHAPE_VIEWS", {'S', 'H', 'V', 'I', 'E', 'W', 'S', '\0'}},
    {SectionKind::kAspects2d, "ASPECTS_2D", {'S', 'H', 'A', 'S', 'P', 'E', 'C', 'T'}},
};

// The entry of a known kind, or nullptr.
inline const SectionKindInfo* FindSectionKind(uint32_t kind) {
  for (const SectionKindInfo& k : kSectionKinds) {
    if (static_cast<uint32_t>(k.kind) == kind) return &k;
  }
  return nullptr;
}

}  // namespace sh
