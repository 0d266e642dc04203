#include "tables/table_file.hpp"

#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include "tables/input_file.hpp"

namespace sh {

MappedFile::~MappedFile() { Close(); }

void MappedFile::Close() {
  if (data_ != nullptr) munmap(data_, size_);
  data_ = nullptr;
  size_ = 0;
}

Status MappedFile::Open(const char* path, const char* what) {
  Close();
  InputFile file;
  SH_RETURN_IF_ERROR(file.Open(path, what, kMaxBlobFileBytes));
  if (file.size() == 0) {
    return Status::Error(StatusCode::kDataLoss, "%s '%s' is empty", what, path);
  }
  void* data = mmap(nullptr, file.size(), PROT_READ, MAP_PRIVATE, file.fd(), 0);
  if (data == MAP_FAILED) {
    return Status::Error(StatusCode::kUnavailable, "cannot map %s '%s': %s", what, path,
                         std::strerror(errno));
  }
  data_ = data;
  size_ = file.size();
  return Status::Ok();
}

Result<uint32_t> FileBlobKinds(const char* path) {
  MappedFile file;
  SH_RETURN_IF_ERROR(file.Open(path, "file"));
  Result<uint32_t> kinds = BlobKinds(file.data(), file.size());
  if (!kinds.ok()) return kinds.status().WithContext("%s", path);
  return kinds;
}

Result<uint32_t> FileBlobCrc32(const char* path) {
  MappedFile file;
  SH_RETURN_IF_ERROR(file.Open(path, "file"));
  if (file.size() < sizeof(SectionBlobPrefix) + sizeof(uint32_t)) {
    return Status::Error(StatusCode::kDataLoss, "'%s' is too short for a blob header (%zu bytes)",
                         path, file.size());
  }
  return BlobHeaderCrc32(file.data(), file.size());
}

}  // namespace sh
