#include "hal/sim/directory_camera_pgm.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

namespace sh::hal {
namespace {

bool IsSpace(uint8_t c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

// Skips whitespace and '#' comments (which run to the end of the line) between header fields.
// Returns false if the data ends first.
bool SkipSpaceAndComments(const uint8_t* data, size_t size, size_t* pos) {
  while (*pos < size) {
    if (IsSpace(data[*pos])) {
      ++*pos;
    } else if (data[*pos] == '#') {
      while (*pos < size && data[*pos] != '\n') ++*pos;
    } else {
      return true;
    }
  }
  return false;
}

enum class FieldResult { kOk, kEnd, kBad };

// Reads a decimal field of at most 7 digits (larger values are refused later anyway).
FieldResult ReadField(const uint8_t* data, size_t size, size_t* pos, int* value) {
  if (!SkipSpaceAndComments(data, size, pos)) return FieldResult::kEnd;
  int v = 0;
  int digits = 0;
  while (*pos < size && data[*pos] >= '0' && data[*pos] <= '9') {
    if (++digits > 7) return FieldResult::kBad;
    v = v * 10 + (data[*pos] - '0');
    ++*pos;
  }
  if (digits == 0) return FieldResult::kBad;
  if (*pos == size) return FieldResult::kEnd;  // the field may continue beyond what we have
  if (!IsSpace(data[*pos])) return FieldResult::kBad;
  *value = v;
  return FieldResult::kOk;
}

// Reads up to `size` bytes at `offset`; returns the count read or -1 with errno set.
ssize_t ReadFully(int fd, uint8_t* dst, size_t size, off_t offset) {
  size_t done = 0;
  while (done < size) {
    const ssize_t n = pread(fd, dst + done, size - done, offset + static_cast<off_t>(done));
    if (n < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (n == 0) break;
    done += static_cast<size_t>(n);
  }
  return static_cast<ssize_t>(done);
}

class File {
 public:
  explicit File(const char* path) : fd_(open(path, O_RDONLY | O_CLOEXEC)) {}
  ~File() {
    if (fd_ >= 0) close(fd_);
  }
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

Status OpenError(const char* path) {
  const int err = errno;
  return Status::Error(err == ENOENT ? StatusCode::kNotFound : StatusCode::kUnavailable,
                       "cannot open %s: %s", PathBaseName(path), std::strerror(err));
}

Status ReadHeaderFrom(int fd, const char* path, PgmHeader* out) {
  uint8_t header[kMaxPgmHeaderBytes];
  const ssize_t n = ReadFully(fd, header, sizeof(header), 0);
  if (n < 0) {
    return Status::Error(StatusCode::kDataLoss, "cannot read %s: %s", PathBaseName(path),
                         std::strerror(errno));
  }
  const Status s = ParsePgmHeader(header, static_cast<size_t>(n), out);
  if (!s.ok()) return Status::Error(s.code(), "%s: %s", PathBaseName(path), s.message());
  return Status::Ok();
}

}  // namespace

const char* PathBaseName(const char* path) {
  const char* slash = std::strrchr(path, '/');
  return slash != nullptr ? slash + 1 : path;
}

Status ParsePgmHeader(const uint8_t* data, size_t size, PgmHeader* out) {
  if (size < 2) return Status::Error(StatusCode::kDataLoss, "file too short for a PGM header");
  if (data[0] != 'P' || (data[1] != '5' && data[1] != '2')) {
    return Status::Error(StatusCode::kInvalidArgument, "not a PGM file (magic is not P5)");
  }
  if (data[1] == '2') {
    return Status::Error(StatusCode::kUnimplemented, "ASCII PGM (P2) not supported, use P5");
  }
  size_t pos = 2;
  if (pos < size && !IsSpace(data[pos]) && data[pos] != '#') {
    return Status::Error(StatusCode::kInvalidArgument, "not a PGM file (junk after P5)");
  }
  int fields[3] = {};
  static const char* const kNames[3] = {"width", "height", "maxval"};
  for (int i = 0; i < 3; ++i) {
    const FieldResult r = ReadField(data, size, &pos, &fields[i]);
    if (r == FieldResult::kEnd) {
      return Status::Error(
          size >= kMaxPgmHeaderBytes ? StatusCode::kInvalidArgument : StatusCode::kDataLoss,
          "PGM header ends before its %s field", kNames[i]);
    }
    if (r == FieldResult::kBad) {
      return Status::Error(StatusCode::kInvalidArgument, "PGM %s field is not a number", kNames[i]);
    }
  }
  const int width = fields[0];
  const int height = fields[1];
  const int max_value = fields[2];
  if (width <= 0 || height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM size %dx%d is empty", width, height);
  }
  if (width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "PGM size %dx%d exceeds %dx%d", width, height,
                         kMaxImageWidth, kMaxImageHeight);
  }
  if (max_value <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "PGM maxval %d is invalid", max_value);
  }
  if (max_value > 255) {
    return Status::Error(StatusCode::kUnimplemented, "16-bit PGM (maxval %d) not supported",
                         max_value);
  }
  out->width = width;
  out->height = height;
  out->max_value = max_value;
  out->data_offset = pos + 1;  // exactly one whitespace byte separates maxval from the pixels
  return Status::Ok();
}

Status ReadPgmHeader(const char* path, PgmHeader* out) {
  File file(path);
  if (file.fd() < 0) return OpenError(path);
  return ReadHeaderFrom(file.fd(), path, out);
}

Status ReadPgmInto(const char* path, GrayView dst) {
  File file(path);
  if (file.fd() < 0) return OpenError(path);
  PgmHeader header;
  SH_RETURN_IF_ERROR(ReadHeaderFrom(file.fd(), path, &header));
  if (header.width != dst.width || header.height != dst.height) {
    return Status::Error(StatusCode::kInvalidArgument, "%s is %dx%d, expected %dx%d",
                         PathBaseName(path), header.width, header.height, dst.width, dst.height);
  }
  const size_t row_bytes = static_cast<size_t>(dst.width);
  for (int y = 0; y < dst.height; ++y) {
    const off_t offset =
        static_cast<off_t>(header.data_offset + row_bytes * static_cast<size_t>(y));
    const ssize_t n = ReadFully(file.fd(), dst.row(y), row_bytes, offset);
    if (n < 0) {
      return Status::Error(StatusCode::kDataLoss, "cannot read %s: %s", PathBaseName(path),
                           std::strerror(errno));
    }
    if (static_cast<size_t>(n) != row_bytes) {
      return Status::Error(StatusCode::kDataLoss, "%s is truncated: %zu of %zu pixel bytes present",
                           PathBaseName(path),
                           row_bytes * static_cast<size_t>(y) + static_cast<size_t>(n),
                           row_bytes * static_cast<size_t>(dst.height));
    }
  }
  return Status::Ok();
}

}  // namespace sh::hal
