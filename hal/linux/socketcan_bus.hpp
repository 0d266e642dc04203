// SocketCAN backend: one CAN_RAW socket bound to a named interface (can0 on the board).
//
// Bus-off: the backend subscribes to error frames (bus-off, controller, restarted, TX timeout,
// no ACK) and reports the controller state through state(); it does not restart the controller
// itself. Restart is the kernel's job, configured on the interface:
//   ip link set can0 type can bitrate 500000 restart-ms 100   (automatic restart after 100 ms)
//   ip link set can0 type can restart                          (manual restart)
// While bus-off, Send() returns kUnavailable if the kernel refuses the frame (ENETDOWN).
//
// Full transmit queue: the kernel answers ENOBUFS when the interface queue (txqueuelen) is full.
// Send() then waits tx_retry_wait_ms and retries up to tx_retry_count times (each wait counted in
// tx_retries) before dropping the frame (tx_dropped_queue_full, kResourceExhausted). The wait is
// a plain sleep for ENOBUFS because POLLOUT tracks the socket buffer, not the interface queue;
// EAGAIN (socket buffer full) waits on POLLOUT.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "hal/can.hpp"

namespace sh::hal {

inline constexpr size_t kSocketCanMaxFilters = 16;
inline constexpr size_t kSocketCanInterfaceNameMax = 16;  // IFNAMSIZ, terminator included

struct SocketCanConfig {
  const char* interface = "can0";
  // Standard (11-bit) ids to receive, e.g. our command id and the NMT id. Empty = receive all.
  uint32_t filter_ids[kSocketCanMaxFilters] = {};
  size_t filter_count = 0;
  int tx_retry_count = 5;
  int tx_retry_wait_ms = 2;
  bool deliver_error_frames = false;  // return error frames from Receive() (e.g. for logging)
  bool receive_own_messages = false;  // loop our own frames back to this socket (tests on vcan)
};

class SocketCanBus final : public CanBus {
 public:
  SocketCanBus() = default;
  ~SocketCanBus() override { Close(); }
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  // Errors: kUnimplemented if the kernel has no AF_CAN (EAFNOSUPPORT), kNotFound if the
  // interface does not exist, kInvalidArgument for a bad configuration, kUnavailable otherwise.
  Status Open(const SocketCanConfig& config);
  void Close();
  bool is_open() const { return fd_ >= 0; }

  Status Send(const CanFrame& frame) override;
  Result<bool> Receive(CanFrame* frame, int timeout_ms) override;
  CanStats stats() const override;
  CanBusState state() const override { return state_.load(std::memory_order_relaxed); }
  const char* name() const override { return interface_; }

 private:
  int fd_ = -1;
  char interface_[kSocketCanInterfaceNameMax] = "can?";
  int tx_retry_count_ = 5;
  int tx_retry_wait_ms_ = 2;
  bool deliver_error_frames_ = false;
  std::atomic<CanBusState> state_{CanBusState::kErrorActive};
  // Send() and Receive() may run on different threads; counters are atomics.
  std::atomic<uint64_t> tx_frames_{0}, rx_frames_{0}, tx_retries_{0}, tx_dropped_{0},
      rx_overflow_{0}, bus_off_events_{0}, error_frames_{0};
};

}  // namespace sh::hal
