#include "tables/model_set.hpp"

#include <cstdio>
#include <cstring>

#include "recog/base/crc32.hpp"
#include "tables/blob_checks.hpp"

namespace sh {
namespace {

// The checks of one directory entry that need nothing but the entry and the blob.
Status CheckEntry(const ModelSetSection& s, uint32_t i, const uint8_t* bytes, uint64_t total,
                  uint64_t first_payload) {
  const char* name = SectionKindName(s.kind);
  if (s.kind == 0)
    return Status::Error(StatusCode::kDataLoss, "model set corrupt: section %u has kind 0", i);
  if (s.reserved0 != 0 || s.reserved1 != 0) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: section %u (%s) has non-zero reserved fields", i,
                         name);
  }
  if (s.offset % kModelSetAlignment != 0) {
    return Status::Error(
        StatusCode::kDataLoss,
        "model set corrupt: section %u (%s) is misaligned (offset not a multiple of 64)", i, name);
  }
  if (s.offset < first_payload) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: section %u (%s) overlaps the header or the directory",
                         i, name);
  }
  if (s.offset > total || s.size > total - s.offset) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set truncated: section %u (%s) ends past the blob (offset %llu, "
                         "%llu bytes, blob %llu bytes)",
                         i, name, static_cast<unsigned long long>(s.offset),
                         static_cast<unsigned long long>(s.size),
                         static_cast<unsigned long long>(total));
  }
  if (s.size < sizeof(SectionBlobPrefix)) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: section %u (%s) is too small for a blob header", i,
                         name);
  }
  const uint8_t* payload = bytes + s.offset;
  SectionBlobPrefix prefix{};
  std::memcpy(&prefix, payload, sizeof(prefix));
  const SectionKindInfo* info = FindSectionKind(s.kind);
  if (info != nullptr && std::memcmp(prefix.magic, info->magic, sizeof(prefix.magic)) != 0) {
    return Status::Error(
        StatusCode::kDataLoss,
        "model set corrupt: section %u (%s) does not hold a %s blob (bad magic number)", i, name,
        name);
  }
  if (prefix.format_version != s.kind_version || prefix.total_size != s.size) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: section %u (%s): directory and section header "
                         "disagree on its version or size",
                         i, name);
  }
  const uint32_t crc = Crc32(payload, static_cast<size_t>(s.size));
  if (crc != s.crc32) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: section %u (%s) CRC-32 %08x, directory says %08x", i,
                         name, crc, s.crc32);
  }
  return Status::Ok();
}

}  // namespace

bool IsModelSet(const void* data, size_t size) {
  return data != nullptr && size >= sizeof(kModelSetMagic) &&
         std::memcmp(data, kModelSetMagic, sizeof(kModelSetMagic)) == 0;
}

const char* SectionKindName(uint32_t kind) {
  const SectionKindInfo* info = FindSectionKind(kind);
  return info == nullptr ? "unknown" : info->name;
}

uint32_t BlobHeaderCrc32(const void* data, size_t size) {
  uint32_t crc = 0;
  if (data == nullptr || size < kBlobCrc32Offset + sizeof(crc)) return 0;
  std::memcpy(&crc, static_cast<const uint8_t*>(data) + kBlobCrc32Offset, sizeof(crc));
  return crc;
}

bool ParseBlobCrc32(const char* text, uint32_t* out) {
  const char* digits = text;
  if (digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) digits += 2;
  const size_t n = std::strlen(digits);
  if (n == 0 || n > 8) return false;
  uint32_t v = 0;
  for (size_t i = 0; i < n; ++i) {
    const char c = digits[i];
    const int d = c >= '0' && c <= '9'   ? c - '0'
                  : c >= 'a' && c <= 'f' ? c - 'a' + 10
                  : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                         : -1;
    if (d < 0) return false;
    v = v << 4 | static_cast<uint32_t>(d);
  }
  *out = v;
  return true;
}

uint32_t ModelSetCrc32(const uint8_t* blob, size_t size) {
  ModelSetHeader header{};
  std::memcpy(&header, blob, sizeof(header));
  header.blob_crc32 = 0;
  const uint32_t crc = Crc32(&header, sizeof(header));
  return Crc32(blob + sizeof(header), size - sizeof(header), crc);
}

Result<ModelSetView> ModelSetView::Open(const void* blob, size_t size) {
  SH_RETURN_IF_ERROR(CheckBlobPrefix(
      blob, size,
      {"model set", kModelSetMagic, kModelSetFormatVersion, sizeof(ModelSetHeader), 8}));
  const auto* bytes = static_cast<const uint8_t*>(blob);
  const auto* h = static_cast<const ModelSetHeader*>(blob);
  if (h->entry_size != sizeof(ModelSetSection)) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: directory entry size field is %u", h->entry_size);
  }
  if (h->reserved0 != 0 || !AllZero(h->reserved1, sizeof(h->reserved1))) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set corrupt: non-zero reserved header fields");
  }
  if (h->section_count == 0 || h->section_count > kMaxModelSetSections) {
    return Status::Error(StatusCode::kDataLoss, "model set corrupt: %u sections (1..%u supported)",
                         h->section_count, kMaxModelSetSections);
  }
  const uint64_t directory_end =
      sizeof(ModelSetHeader) + uint64_t{h->section_count} * sizeof(ModelSetSection);
  if (directory_end > size) {
    return Status::Error(StatusCode::kDataLoss,
                         "model set truncated: the directory of %u sections ends past the blob",
                         h->section_count);
  }
  const auto* dir = reinterpret_cast<const ModelSetSection*>(bytes + sizeof(ModelSetHeader));
  for (uint32_t i = 0; i < h->section_count; ++i) {
    SH_RETURN_IF_ERROR(CheckEntry(dir[i], i, bytes, size, directory_end));
    for (uint32_t j = 0; j < i; ++j) {
      if (dir[j].kind == dir[i].kind) {
        return Status::Error(StatusCode::kDataLoss,
                             "model set corrupt: sections %u and %u both hold kind %u (%s)", j, i,
                             dir[i].kind, SectionKindName(dir[i].kind));
      }
      const bool apart = dir[i].offset + dir[i].size <= dir[j].offset ||
                         dir[j].offset + dir[j].size <= dir[i].offset;
      if (!apart) {
        return Status::Error(StatusCode::kDataLoss,
                             "model set corrupt: section %u (%s) overlaps section %u (%s)", i,
                             SectionKindName(dir[i].kind), j, SectionKindName(dir[j].kind));
      }
    }
  }
  // Last, the whole blob: header, directory and padding (a damaged section was named above).
  SH_RETURN_IF_ERROR(CheckBlobCrc32(bytes, size, "model set"));
  ModelSetView view;
  view.bytes_ = bytes;
  view.header_ = h;
  view.directory_ = dir;
  return view;
}

bool ModelSetView::Has(SectionKind kind) const {
  for (uint32_t i = 0; i < section_count(); ++i) {
    if (directory_[i].kind == static_cast<uint32_t>(kind)) return true;
  }
  return false;
}

Result<BlobSpan> ModelSetView::FindSection(SectionKind kind) const {
  for (uint32_t i = 0; i < section_count(); ++i) {
    if (directory_[i].kind == static_cast<uint32_t>(kind)) return payload(i);
  }
  return Status::Error(StatusCode::kNotFound, "model set has no %s section",
                       SectionKindName(static_cast<uint32_t>(kind)));
}

Result<BlobSpan> SectionOrBareBlob(const void* data, size_t size, SectionKind kind) {
  if (!IsModelSet(data, size)) return BlobSpan{data, size};
  SH_ASSIGN_OR_RETURN(const ModelSetView set, ModelSetView::Open(data, size));
  return set.FindSection(kind);
}

Result<uint32_t> BlobKinds(const void* data, size_t size) {
  if (IsModelSet(data, size)) {
    SH_ASSIGN_OR_RETURN(const ModelSetView set, ModelSetView::Open(data, size));
    uint32_t kinds = 0;
    for (uint32_t i = 0; i < set.section_count(); ++i) {
      if (set.section(i).kind < 32) kinds |= 1u << set.section(i).kind;
    }
    return kinds;
  }
  for (const SectionKindInfo& k : kSectionKinds) {
    if (data != nullptr && size >= sizeof(k.magic) &&
        std::memcmp(data, k.magic, sizeof(k.magic)) == 0)
      return KindBit(k.kind);
  }
  return uint32_t{0};
}

}  // namespace sh
