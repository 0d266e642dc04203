#include "tables/table_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace sh {

MappedFile::~MappedFile() { Close(); }

void MappedFile::Close() {
  if (data_ != nullptr) munmap(data_, size_);
  data_ = nullptr;
  size_ = 0;
}

Status MappedFile::Open(const char* path, const char* what) {
  Close();
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    return Status::Error(StatusCode::kNotFound, "cannot open %s '%s': %s", what, path,
                         std::strerror(errno));
  }
  struct stat st {};
  if (fstat(fd, &st) != 0 || st.st_size <= 0) {
    ::close(fd);
    return Status::Error(StatusCode::kDataLoss, "%s '%s' is empty or unreadable", what, path);
  }
  void* data = mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (data == MAP_FAILED) {
    return Status::Error(StatusCode::kUnavailable, "cannot map %s '%s': %s", what, path,
                         std::strerror(errno));
  }
  data_ = data;
  size_ = size_t(st.st_size);
  return Status::Ok();
}

Result<uint32_t> FileBlobKinds(const char* path) {
  MappedFile file;
  SH_RETURN_IF_ERROR(file.Open(path, "file"));
  Result<uint32_t> kinds = BlobKinds(file.data(), file.size());
  if (!kinds.ok()) return kinds.status().WithContext("%s", path);
  return kinds;
}

}  // namespace sh
