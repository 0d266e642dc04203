#include "firmware/node_id_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/canopen/cob_id.hpp"
#include "recog/base/printable.hpp"
#include "tables/input_file.hpp"

namespace sh::fw {

Result<uint8_t> ReadNodeIdFile(const char* path) {
  char text[16] = {};
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "node id file", text, sizeof(text) - 1, &n));
  // The line end is no part of the value, in the check or in the message.
  while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r' || text[n - 1] == ' ')) --n;
  text[n] = '\0';
  char* end = nullptr;
  const long id = std::strtol(text, &end, 10);
  const bool in_range = (id >= protocol::kNodeIdMin && id <= protocol::kNodeIdMax) ||
                        id == canopen::kNodeIdUnconfigured;
  if (end == text || end == nullptr || *end != '\0' || !in_range) {
    char shown[4 * sizeof(text) + 4];
    return Status::Error(StatusCode::kInvalidArgument,
                         "node id file %s holds '%s', not a node id 1..127 or 255 (unconfigured)",
                         path, Printable(text, n, shown, sizeof(shown)));
  }
  return static_cast<uint8_t>(id);
}

NodeIdFile::NodeIdFile(const char* path) { std::snprintf(path_, sizeof(path_), "%s", path); }

Status NodeIdFile::StoreNodeId(uint8_t node_id) {
  if ((node_id < protocol::kNodeIdMin || node_id > protocol::kNodeIdMax) &&
      node_id != canopen::kNodeIdUnconfigured) {
    return Status::Error(StatusCode::kOutOfRange, "node id %u cannot be stored", node_id);
  }
  char tmp[kConfigPathMax + 8];
  std::snprintf(tmp, sizeof(tmp), "%s.tmp", path_);
  const int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s: %s", tmp,
                         std::strerror(errno));
  }
  char text[8];
  const int len = std::snprintf(text, sizeof(text), "%u\n", node_id);
  const bool written = write(fd, text, static_cast<size_t>(len)) == len && fsync(fd) == 0;
  close(fd);
  if (!written || std::rename(tmp, path_) != 0) {
    const int err = errno;
    (void)unlink(tmp);
    return Status::Error(StatusCode::kUnavailable, "cannot store the node id in %s: %s", path_,
                         std::strerror(err));
  }
  return Status::Ok();
}

}  // namespace sh::fw
