#include "firmware/sd_notify.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>

namespace sh::fw {

Status SdNotifier::Open() {
  const char* socket_name = std::getenv("NOTIFY_SOCKET");
  const char* watchdog = std::getenv("WATCHDOG_USEC");
  if (watchdog != nullptr) watchdog_usec_ = std::strtoull(watchdog, nullptr, 10);
  if (socket_name == nullptr || socket_name[0] == '\0') return Status::Ok();
  const size_t len = std::strlen(socket_name);
  if ((socket_name[0] != '/' && socket_name[0] != '@') || len >= sizeof(path_)) {
    return Status::Error(StatusCode::kInvalidArgument, "NOTIFY_SOCKET '%s' is not usable",
                         socket_name);
  }
  std::memcpy(path_, socket_name, len);
  if (path_[0] == '@') path_[0] = '\0';  // abstract namespace
  path_len_ = static_cast<unsigned>(len);
  fd_ = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    return Status::Error(StatusCode::kUnavailable, "notify socket: %s", std::strerror(errno));
  }
  return Status::Ok();
}

SdNotifier::~SdNotifier() {
  if (fd_ >= 0) close(fd_);
}

Status SdNotifier::Notify(const char* state) {
  if (fd_ < 0) return Status::Ok();
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, path_, path_len_);
  const socklen_t addr_len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + path_len_);
  const size_t n = std::strlen(state);
  const ssize_t sent =
      sendto(fd_, state, n, MSG_NOSIGNAL, reinterpret_cast<sockaddr*>(&addr), addr_len);
  if (sent != static_cast<ssize_t>(n)) {
    return Status::Error(StatusCode::kUnavailable, "sd_notify '%s': %s", state,
                         std::strerror(errno));
  }
  return Status::Ok();
}

}  // namespace sh::fw
