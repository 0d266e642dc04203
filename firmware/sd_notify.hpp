// systemd service notification (sd_notify protocol) without libsystemd: one datagram with
// "READY=1", "WATCHDOG=1", "STATUS=..." to the AF_UNIX socket named by $NOTIFY_SOCKET
// (a path, or an abstract address when it starts with '@'). Without the variable (not started
// by systemd, or Type=simple) every call is a no-op.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::fw {

class SdNotifier {
 public:
  // Reads $NOTIFY_SOCKET and $WATCHDOG_USEC once and opens the datagram socket.
  Status Open();
  ~SdNotifier();
  bool enabled() const { return fd_ >= 0; }
  // Watchdog period systemd expects pings within (WatchdogSec), 0 when not configured.
  uint64_t watchdog_usec() const { return watchdog_usec_; }

  Status Notify(const char* state);  // e.g. "READY=1\nSTATUS=ready"

 private:
  int fd_ = -1;
  char path_[108] = {};  // sun_path
  unsigned path_len_ = 0;
  uint64_t watchdog_usec_ = 0;
};

}  // namespace sh::fw
