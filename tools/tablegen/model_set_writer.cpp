#include "tools/tablegen/model_set_writer.hpp"

#include <cstring>

#include "recog/base/crc32.hpp"
#include "tables/model_set.hpp"
#include "tools/tablegen/blob_writer.hpp"

namespace sh {
namespace {

size_t AlignUp(size_t n) {
  return (n + kModelSetAlignment - 1) / kModelSetAlignment * kModelSetAlignment;
}

Status CheckInput(const ModelSetInput& in, size_t index) {
  const char* name = SectionKindName(in.kind);
  if (in.kind == 0)
    return Status::Error(StatusCode::kInvalidArgument, "model set: section %zu has kind 0", index);
  if (in.data == nullptr || in.size < sizeof(SectionBlobPrefix)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "model set: section %zu (%s) is too small for a blob header", index, name);
  }
  SectionBlobPrefix prefix{};
  std::memcpy(&prefix, in.data, sizeof(prefix));
  const SectionKindInfo* info = FindSectionKind(in.kind);
  if (info != nullptr && std::memcmp(prefix.magic, info->magic, sizeof(info->magic)) != 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "model set: section %zu is not a %s blob (bad magic number)", index, name);
  }
  if (prefix.total_size != in.size) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "model set: section %zu (%s) says %llu bytes, %zu given", index, name,
                         static_cast<unsigned long long>(prefix.total_size), in.size);
  }
  return Status::Ok();
}

}  // namespace

Result<std::vector<uint8_t>> BuildModelSet(const std::vector<ModelSetInput>& sections) {
  if (sections.empty() || sections.size() > kMaxModelSetSections) {
    return Status::Error(StatusCode::kInvalidArgument, "model set: %zu sections (1..%u supported)",
                         sections.size(), kMaxModelSetSections);
  }
  for (size_t i = 0; i < sections.size(); ++i) {
    SH_RETURN_IF_ERROR(CheckInput(sections[i], i));
    for (size_t j = 0; j < i; ++j) {
      if (sections[j].kind == sections[i].kind) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "model set: sections %zu and %zu are both %s", j, i,
                             SectionKindName(sections[i].kind));
      }
    }
  }
  ModelSetHeader header{};
  std::memcpy(header.magic, kModelSetMagic, sizeof(header.magic));
  header.format_version = kModelSetFormatVersion;
  header.header_size = sizeof(ModelSetHeader);
  header.section_count = static_cast<uint32_t>(sections.size());
  header.entry_size = sizeof(ModelSetSection);
  std::vector<ModelSetSection> directory(sections.size());
  size_t end = AlignUp(sizeof(ModelSetHeader) + sections.size() * sizeof(ModelSetSection));
  for (size_t i = 0; i < sections.size(); ++i) {
    ModelSetSection& d = directory[i];
    SectionBlobPrefix prefix{};
    std::memcpy(&prefix, sections[i].data, sizeof(prefix));
    d.kind = sections[i].kind;
    d.kind_version = prefix.format_version;
    d.offset = end;
    d.size = sections[i].size;
    d.crc32 = Crc32(sections[i].data, sections[i].size);
    end = AlignUp(end + sections[i].size);
  }
  header.total_size = end;
  std::vector<uint8_t> blob(end, 0);
  std::memcpy(blob.data() + sizeof(header), directory.data(),
              directory.size() * sizeof(ModelSetSection));
  for (size_t i = 0; i < sections.size(); ++i) {
    std::memcpy(blob.data() + directory[i].offset, sections[i].data, sections[i].size);
  }
  SealBlob(blob, header);
  return blob;
}

}  // namespace sh
