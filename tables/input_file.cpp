#include "tables/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace sh {

const char* FileTypeName(unsigned mode) {
  switch (mode & S_IFMT) {
    case S_IFREG:
      return "a regular file";
    case S_IFDIR:
      return "a directory";
    case S_IFIFO:
      return "a FIFO";
    case S_IFCHR:
      return "a character device";
    case S_IFBLK:
      return "a block device";
    case S_IFSOCK:
      return "a socket";
    default:
      return "not a regular file";
  }
}

InputFile::~InputFile() { Close(); }

void InputFile::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  size_ = 0;
}

Status InputFile::Open(const char* path, const char* what, size_t max_bytes) {
  Close();
  std::snprintf(path_, sizeof(path_), "%s", path);
  std::snprintf(what_, sizeof(what_), "%s", what);
  max_bytes_ = max_bytes;
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer, forever.
  int fd = -1;
  do {
    fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) {
    const int err = errno;
    return Status::Error(err == ENOENT ? StatusCode::kNotFound : StatusCode::kUnavailable,
                         "cannot open %s '%s': %s", what, path, std::strerror(err));
  }
  struct stat st {};
  if (fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return Status::Error(StatusCode::kUnavailable, "cannot stat %s '%s': %s", what, path,
                         std::strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status::Error(StatusCode::kInvalidArgument, "%s '%s' is %s, not a regular file", what,
                         path, FileTypeName(unsigned(st.st_mode)));
  }
  if (st.st_size < 0 || uint64_t(st.st_size) > uint64_t(max_bytes)) {
    ::close(fd);
    return Status::Error(StatusCode::kOutOfRange,
                         "%s '%s' is %lld bytes, larger than the %zu-byte limit", what, path,
                         static_cast<long long>(st.st_size), max_bytes);
  }
  fd_ = fd;
  size_ = size_t(st.st_size);
  return Status::Ok();
}

Status InputFile::ReadAll(char* buffer, size_t capacity, size_t* length) {
  if (fd_ < 0) return Status::Error(StatusCode::kFailedPrecondition, "no file open");
  const size_t limit = capacity < max_bytes_ ? capacity : max_bytes_;
  size_t size = 0;
  for (;;) {
    // One byte more than the bound reveals a file that grew (or a /proc file that lied).
    char extra;
    char* dst = size < limit ? buffer + size : &extra;
    const size_t want = size < limit ? limit - size : 1;
    const ssize_t n = ::read(fd_, dst, want);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      return Status::Error(StatusCode::kDataLoss, "cannot read %s '%s': %s", what_, path_,
                           std::strerror(errno));
    }
    if (n == 0) break;
    if (size >= limit && limit < max_bytes_) {
      return Status::Error(StatusCode::kOutOfRange, "%s '%s' grew past %zu bytes while it was read",
                           what_, path_, limit);
    }
    if (size >= limit) {
      return Status::Error(StatusCode::kOutOfRange, "%s '%s' is larger than the %zu-byte limit",
                           what_, path_, limit);
    }
    size += size_t(n);
  }
  *length = size;
  return Status::Ok();
}

Status ReadInputFile(const char* path, const char* what, char* buffer, size_t capacity,
                     size_t* length) {
  InputFile file;
  SH_RETURN_IF_ERROR(file.Open(path, what, capacity));
  return file.ReadAll(buffer, capacity, length);
}

Status ReadInputFile(const std::string& path, const char* what, size_t max_bytes,
                     std::string* text) {
  InputFile file;
  SH_RETURN_IF_ERROR(file.Open(path.c_str(), what, max_bytes));
  // Sized from fstat; a file that reports 0 bytes (/proc, sysfs) gets the whole bound.
  const size_t capacity = file.size() == 0 ? max_bytes : file.size();
  text->assign(capacity, '\0');
  size_t length = 0;
  SH_RETURN_IF_ERROR(file.ReadAll(&(*text)[0], text->size(), &length));
  text->resize(length);
  return Status::Ok();
}

}  // namespace sh
