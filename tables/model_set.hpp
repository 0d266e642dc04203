// The model-set container's validating reader (tables/model_set_format.hpp): zero-copy over a
// mapped file or linked-in data, no heap. Open() checks every header and directory field against
// its range (sizes, offsets inside the blob, alignment, no overlap, no kind twice, each payload's
// CRC and common header) and the whole blob's CRC before anything is used; FindSection() then
// hands out a payload that the kind's own view opens exactly as it opens a bare blob.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "tables/model_set_format.hpp"

namespace sh {

// Bytes of a blob: a whole file, or one section of a model set.
struct BlobSpan {
  const void* data = nullptr;
  size_t size = 0;
};

// Whether `data` starts with the model-set magic (nothing else is checked).
bool IsModelSet(const void* data, size_t size);

// The kind's name for messages ("HASH3D"), "unknown" for a kind this build does not know.
const char* SectionKindName(uint32_t kind);

// The container's CRC-32: every byte of [0, size) with blob_crc32 read as zero. `blob` holds at
// least sizeof(ModelSetHeader) bytes.
uint32_t ModelSetCrc32(const uint8_t* blob, size_t size);

// A blob's identity: the whole-blob CRC-32 its header carries (a model set's, or a bare blob's of
// any kind), as `stereohash tables info` prints it. Read, not checked: the blob's view checks it.
// 0 when `size` is shorter than the header's prefix and CRC.
uint32_t BlobHeaderCrc32(const void* data, size_t size);
// A CRC-32 as text: "0", or one to eight hex digits with an optional 0x (as `tables info` prints
// it, or as a C literal). Nothing else: no sign, no blanks, no ninth digit.
bool ParseBlobCrc32(const char* text, uint32_t* out);

class ModelSetView {
 public:
  ModelSetView() = default;

  // Validates the container in place: `blob` 8-byte aligned, `size` bytes.
  static Result<ModelSetView> Open(const void* blob, size_t size);

  const ModelSetHeader& header() const { return *header_; }
  uint32_t section_count() const { return header_ == nullptr ? 0 : header_->section_count; }
  const ModelSetSection& section(uint32_t i) const { return directory_[i]; }
  BlobSpan payload(uint32_t i) const {
    return {bytes_ + directory_[i].offset, static_cast<size_t>(directory_[i].size)};
  }
  bool Has(SectionKind kind) const;
  // The payload of `kind`; kNotFound naming the kind when the set holds none.
  Result<BlobSpan> FindSection(SectionKind kind) const;

 private:
  const uint8_t* bytes_ = nullptr;
  const ModelSetHeader* header_ = nullptr;
  const ModelSetSection* directory_ = nullptr;
};

// A blob that is either a model set or a bare blob of one kind (the single-kind files): the
// payload of `kind` in a model set (validated container), or the whole blob otherwise (its own
// view validates it).
Result<BlobSpan> SectionOrBareBlob(const void* data, size_t size, SectionKind kind);

// The kinds a blob holds, as bits (1 << kind): a model set's sections, or the one kind of a bare
// blob by its magic (0 for anything else). A damaged model set is an error.
Result<uint32_t> BlobKinds(const void* data, size_t size);
inline constexpr uint32_t KindBit(SectionKind kind) { return 1u << static_cast<uint32_t>(kind); }

}  // namespace sh
