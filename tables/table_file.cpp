#include "tables/table_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace sh {

MappedTable::~MappedTable() { Close(); }

void MappedTable::Close() {
  if (data_ != nullptr) munmap(data_, size_);
  data_ = nullptr;
  size_ = 0;
  view_ = TableView();
}

Status MappedTable::Open(const char* path) {
  Close();
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    return Status::Error(StatusCode::kNotFound, "cannot open table file '%s': %s", path,
                         std::strerror(errno));
  struct stat st {};
  if (fstat(fd, &st) != 0 || st.st_size <= 0) {
    ::close(fd);
    return Status::Error(StatusCode::kDataLoss, "table file '%s' is empty or unreadable", path);
  }
  void* data = mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
  ::close(fd);
  if (data == MAP_FAILED)
    return Status::Error(StatusCode::kUnavailable, "cannot map table file '%s': %s", path,
                         std::strerror(errno));
  Result<TableView> view = TableView::Open(data, size_t(st.st_size));
  if (!view.ok()) {
    munmap(data, size_t(st.st_size));
    return view.status().WithContext("%s", path);
  }
  data_ = data;
  size_ = size_t(st.st_size);
  view_ = *view;
  return Status::Ok();
}

}  // namespace sh
