// What every builder does to write a blob the readers take (tables/blob_checks.hpp): the
// sections laid out behind the header, each at the next multiple of kSectionAlignment; the
// records copied in; the header written with the CRC-32 of the whole blob; and the counting
// sort that groups hash entries by bin.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "recog/base/crc32.hpp"
#include "tables/blob_checks.hpp"

namespace sh {

// Places sections one after another behind a header of `header_size` bytes.
class SectionLayout {
 public:
  explicit SectionLayout(size_t header_size) : end_(AlignSection(header_size)) {}

  void Place(SectionRef* section, size_t bytes) {
    section->offset = end_;
    section->size = bytes;
    end_ = AlignSection(end_ + bytes);
  }
  // The blob's size: the end of the last section, aligned.
  size_t total_size() const { return end_; }

 private:
  size_t end_;
};

// Copies `count` records into their section of `blob` (sized by SectionLayout).
template <typename T>
void PutSection(std::vector<uint8_t>& blob, const SectionRef& section, const T* data,
                size_t count) {
  if (count != 0) std::memcpy(blob.data() + section.offset, data, count * sizeof(T));
}

// Writes `header` at the blob's start with blob_crc32 set to the CRC-32 of the whole blob, the
// header included, with that field read as zero (what CheckBlobCrc32 compares).
template <typename Header>
void SealBlob(std::vector<uint8_t>& blob, Header& header) {
  static_assert(offsetof(Header, blob_crc32) == kBlobCrc32Offset);
  header.blob_crc32 = 0;
  std::memcpy(blob.data(), &header, sizeof(header));
  header.blob_crc32 = BlobCrc32(blob.data(), blob.size(), kBlobCrc32Offset);
  std::memcpy(blob.data(), &header, sizeof(header));
}

// Counting sort of items by bin: bin b holds items order[offsets[b] .. offsets[b + 1]), in
// their original order. Returns offsets (bins + 1 entries); *max_per_bin is the fullest bin.
std::vector<uint32_t> SortByBin(const std::vector<uint32_t>& bin_of_item, uint32_t bins,
                                std::vector<uint32_t>* order, uint32_t* max_per_bin);

}  // namespace sh
