#include "hal/linux/socketcan_bus.hpp"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "hal/linux/socketcan_errors.hpp"

namespace sh::hal {
namespace {

int64_t MonotonicMs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

}  // namespace

Status SocketCanBus::Open(const SocketCanConfig& config) {
  Close();
  if (config.interface == nullptr || config.interface[0] == '\0' ||
      std::strlen(config.interface) >= kSocketCanInterfaceNameMax) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "socketcan: interface name must have 1..%zu characters",
                         kSocketCanInterfaceNameMax - 1);
  }
  if (config.filter_count > kSocketCanMaxFilters) {
    return Status::Error(StatusCode::kInvalidArgument, "socketcan: %zu filters, at most %zu",
                         config.filter_count, kSocketCanMaxFilters);
  }
  if (config.tx_retry_count < 0 || config.tx_retry_wait_ms < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "socketcan: retry count and wait must not be negative");
  }
  std::snprintf(interface_, sizeof(interface_), "%s", config.interface);
  tx_retry_count_ = config.tx_retry_count;
  tx_retry_wait_ms_ = config.tx_retry_wait_ms;
  deliver_error_frames_ = config.deliver_error_frames;
  state_ = CanBusState::kErrorActive;

  const int fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int err = errno;
    if (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) {
      return Status::Error(StatusCode::kUnimplemented,
                           "socketcan: the kernel has no AF_CAN/CAN_RAW support (%s)",
                           std::strerror(err));
    }
    return Status::Error(StatusCode::kUnavailable, "socketcan: socket(PF_CAN): %s",
                         std::strerror(err));
  }
  auto fail = [fd](StatusCode code, const char* what, int err) {
    close(fd);
    return Status::Error(code, "socketcan: %s: %s", what, std::strerror(err));
  };

  const unsigned ifindex = if_nametoindex(config.interface);
  if (ifindex == 0) {
    const int err = errno;
    close(fd);
    return Status::Error(StatusCode::kNotFound, "socketcan: CAN interface '%s' not found (%s)",
                         config.interface, std::strerror(err));
  }

  if (config.filter_count > 0) {
    can_filter filters[kSocketCanMaxFilters];
    for (size_t i = 0; i < config.filter_count; ++i) {
      if (config.filter_ids[i] > CAN_SFF_MASK) {
        close(fd);
        return Status::Error(StatusCode::kInvalidArgument,
                             "socketcan: filter id 0x%X is not an 11-bit id", config.filter_ids[i]);
      }
      // Match the exact standard id, data frames only (EFF and RTR bits must be clear).
      filters[i].can_id = config.filter_ids[i];
      filters[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters,
                   static_cast<socklen_t>(sizeof(can_filter) * config.filter_count)) != 0) {
      return fail(StatusCode::kUnavailable, "CAN_RAW_FILTER", errno);
    }
  }
  const can_err_mask_t err_mask = SocketCanErrorMask();
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask)) != 0) {
    return fail(StatusCode::kUnavailable, "CAN_RAW_ERR_FILTER", errno);
  }
  const int own = config.receive_own_messages ? 1 : 0;
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof(own)) != 0) {
    return fail(StatusCode::kUnavailable, "CAN_RAW_RECV_OWN_MSGS", errno);
  }
  const int on = 1;
  // Kernel receive timestamps (closer to the wire than a clock read after poll) and the count
  // of frames the socket dropped because its receive buffer was full.
  if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof(on)) != 0) {
    return fail(StatusCode::kUnavailable, "SO_TIMESTAMP", errno);
  }
  if (setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof(on)) != 0) {
    return fail(StatusCode::kUnavailable, "SO_RXQ_OVFL", errno);
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(ifindex);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    return fail(StatusCode::kUnavailable, "bind", errno);
  }
  fd_ = fd;
  return Status::Ok();
}

void SocketCanBus::Close() {
  if (fd_ >= 0) {
    close(fd_);
    fd_ = -1;
  }
}

Status SocketCanBus::Send(const CanFrame& frame) {
  if (fd_ < 0) {
    return Status::Error(StatusCode::kFailedPrecondition, "socketcan: Send() before Open()");
  }
  SH_RETURN_IF_ERROR(ValidateCanFrame(frame));
  can_frame cf{};
  cf.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0u) | (frame.rtr ? CAN_RTR_FLAG : 0u);
  cf.can_dlc = frame.len;
  std::memcpy(cf.data, frame.data, frame.len);

  for (int attempt = 0;; ++attempt) {
    const ssize_t n = send(fd_, &cf, sizeof(cf), MSG_DONTWAIT);
    if (n == static_cast<ssize_t>(sizeof(cf))) {
      tx_frames_.fetch_add(1, std::memory_order_relaxed);
      return Status::Ok();
    }
    const int err = n < 0 ? errno : EIO;
    if (err == EINTR) continue;
    if (err == ENOBUFS || err == EAGAIN) {
      if (attempt >= tx_retry_count_) {
        tx_dropped_.fetch_add(1, std::memory_order_relaxed);
        return Status::Error(StatusCode::kResourceExhausted,
                             "socketcan: %s transmit queue full; frame 0x%X dropped after %d "
                             "retries",
                             interface_, frame.id, tx_retry_count_);
      }
      tx_retries_.fetch_add(1, std::memory_order_relaxed);
      pollfd pfd{fd_, POLLOUT, 0};
      // ENOBUFS: the interface queue is full and POLLOUT would report ready at once, so wait
      // without watching the socket.
      poll(err == EAGAIN ? &pfd : nullptr, err == EAGAIN ? 1 : 0, tx_retry_wait_ms_);
      continue;
    }
    if (err == ENETDOWN) {
      return Status::Error(StatusCode::kUnavailable,
                           "socketcan: %s is down or bus-off (state %s); frame 0x%X not sent",
                           interface_, CanBusStateName(state()), frame.id);
    }
    return Status::Error(StatusCode::kUnavailable, "socketcan: send on %s: %s", interface_,
                         std::strerror(err));
  }
}

Result<bool> SocketCanBus::Receive(CanFrame* frame, int timeout_ms) {
  if (fd_ < 0) {
    return Status::Error(StatusCode::kFailedPrecondition, "socketcan: Receive() before Open()");
  }
  if (frame == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "socketcan: Receive() needs a frame");
  }
  const int64_t deadline = timeout_ms >= 0 ? MonotonicMs() + timeout_ms : 0;
  for (;;) {
    int wait_ms = -1;
    if (timeout_ms >= 0) {
      const int64_t left = deadline - MonotonicMs();
      wait_ms = left > 0 ? static_cast<int>(left) : 0;
    }
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = poll(&pfd, 1, wait_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      return Status::Error(StatusCode::kUnavailable, "socketcan: poll on %s: %s", interface_,
                           std::strerror(errno));
    }
    if (ready == 0) return false;

    can_frame cf{};
    iovec iov{&cf, sizeof(cf)};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(uint32_t))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof(control);
    const ssize_t n = recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return Status::Error(StatusCode::kUnavailable, "socketcan: recvmsg on %s: %s", interface_,
                           std::strerror(errno));
    }
    if (n != static_cast<ssize_t>(sizeof(cf))) {
      // CAN FD frames only arrive with CAN_RAW_FD_FRAMES enabled, which we never set.
      return Status::Error(StatusCode::kDataLoss, "socketcan: short read of %zd bytes on %s", n,
                           interface_);
    }
    CanFrame out;
    out.timestamp_us = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SO_TIMESTAMP) {
        timeval tv;
        std::memcpy(&tv, CMSG_DATA(c), sizeof(tv));
        out.timestamp_us =
            static_cast<uint64_t>(tv.tv_sec) * 1000000u + static_cast<uint64_t>(tv.tv_usec);
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        uint32_t dropped;
        std::memcpy(&dropped, CMSG_DATA(c), sizeof(dropped));
        rx_overflow_.store(dropped, std::memory_order_relaxed);  // cumulative in the kernel
      }
    }
    if (out.timestamp_us == 0) out.timestamp_us = CanNowUs();
    out.len = cf.can_dlc <= kCanMaxDataBytes ? cf.can_dlc : kCanMaxDataBytes;
    std::memcpy(out.data, cf.data, out.len);
    if (cf.can_id & CAN_ERR_FLAG) {
      out.error = true;
      out.id = cf.can_id & CAN_ERR_MASK;
      error_frames_.fetch_add(1, std::memory_order_relaxed);
      const CanErrorUpdate update = ApplyCanErrorFrame(state(), out.id, cf.data);
      if (update.entered_bus_off) bus_off_events_.fetch_add(1, std::memory_order_relaxed);
      state_.store(update.state, std::memory_order_relaxed);
      if (!deliver_error_frames_) continue;
      *frame = out;
      return true;
    }
    out.extended = (cf.can_id & CAN_EFF_FLAG) != 0;
    out.rtr = (cf.can_id & CAN_RTR_FLAG) != 0;
    out.id = cf.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    rx_frames_.fetch_add(1, std::memory_order_relaxed);
    *frame = out;
    return true;
  }
}

CanStats SocketCanBus::stats() const {
  CanStats s;
  s.tx_frames = tx_frames_.load(std::memory_order_relaxed);
  s.rx_frames = rx_frames_.load(std::memory_order_relaxed);
  s.tx_retries = tx_retries_.load(std::memory_order_relaxed);
  s.tx_dropped_queue_full = tx_dropped_.load(std::memory_order_relaxed);
  s.rx_dropped_overflow = rx_overflow_.load(std::memory_order_relaxed);
  s.bus_off_events = bus_off_events_.load(std::memory_order_relaxed);
  s.error_frames = error_frames_.load(std::memory_order_relaxed);
  return s;
}

}  // namespace sh::hal
