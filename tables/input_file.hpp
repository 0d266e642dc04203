// Opening and reading input files without ever blocking, bounded in size: every file a user, a
// configuration or a model folder names goes through here.
#pragma once

#include <cstddef>
#include <string>

#include "recog/base/status.hpp"

namespace sh {

// The largest blob file (model set, bare hash table, aspect table, view or feature database)
// that is mapped: the largest feature database (64 MiB of texels) and its tables fit with room.
inline constexpr size_t kMaxBlobFileBytes = size_t{256} << 20;

// A regular file opened read-only. Open() never blocks: the file is opened with O_NONBLOCK, so
// a FIFO without a writer returns at once, and anything that is not a regular file (FIFO,
// character or block device such as /dev/zero, socket, directory) is refused by name before a
// byte is read. A file larger than `max_bytes` is refused from its size alone, so a huge or
// sparse file is never read.
class InputFile {
 public:
  InputFile() = default;
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // `what` names the kind of file in messages ("calibration", "OBJ").
  Status Open(const char* path, const char* what, size_t max_bytes);
  // Reads the whole file into `buffer` (at least `max_bytes` of Open()); refuses a file that grew
  // past the bound since Open(). The size is read again, not taken from Open(): /proc and sysfs
  // files report 0.
  Status ReadAll(char* buffer, size_t capacity, size_t* length);
  void Close();
  int fd() const { return fd_; }
  // The size fstat() reported at Open().
  size_t size() const { return size_; }

 private:
  int fd_ = -1;
  size_t size_ = 0;
  size_t max_bytes_ = 0;
  char path_[128] = {};
  char what_[32] = {};
};

// Reads the whole regular file `path` of at most `capacity` bytes into `buffer`; the errors of
// InputFile, naming `what` and the path.
Status ReadInputFile(const char* path, const char* what, char* buffer, size_t capacity,
                     size_t* length);

// Host convenience: the same into a string (model folders, tool inputs; never per frame).
Status ReadInputFile(const std::string& path, const char* what, size_t max_bytes,
                     std::string* text);

// "a FIFO", "a directory", "a character device", ...: what a non-regular st_mode is.
const char* FileTypeName(unsigned mode);

}  // namespace sh
