// In-process simulated CAN bus: several endpoints (firmware, socketcand server, tests) share one
// medium. A frame sent by one endpoint is queued at every other endpoint whose filter accepts it,
// like on a real bus (no loopback to the sender).
//
// Capacities are fixed at compile time: kSimCanMaxEndpoints endpoints, each with a receive ring
// of queue_depth frames (kSimCanQueueDepth by default, like a SocketCAN socket's receive buffer;
// up to kSimCanMaxQueueDepth for a bridge that relays a whole burst). AddEndpoint() allocates
// the ring of the configured depth (QueueBytes(queue_depth)), once; a full receive ring drops
// the new frame and counts it in that endpoint's rx_dropped_overflow (what a real controller
// does when software reads too slowly).
//
// Fault injection mimics the two failures the firmware must survive:
//  - bus-off: the endpoint's Send() fails with kUnavailable until RecoverFromBusOff() (what the
//    kernel's restart-ms or `ip link set canX type can restart` does on the board);
//  - transmit queue full: the next N transmit attempts find the queue full, exercising the same
//    bounded retry/drop path as ENOBUFS on SocketCAN.
// All methods are thread-safe (one mutex for the whole bus; a condition variable per endpoint).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>

#include "hal/can.hpp"

namespace sh::hal {

inline constexpr size_t kSimCanMaxEndpoints = 8;
inline constexpr size_t kSimCanQueueDepth = 512;
inline constexpr size_t kSimCanMaxQueueDepth = 4096;
inline constexpr size_t kSimCanMaxFilters = 16;
inline constexpr size_t kSimCanNameMax = 16;

struct SimCanEndpointConfig {
  const char* name = "can0";
  uint32_t filter_ids[kSimCanMaxFilters] = {};  // exact ids to accept; empty = accept all
  size_t filter_count = 0;
  size_t queue_depth = kSimCanQueueDepth;  // receive ring, 1..kSimCanMaxQueueDepth frames
  int tx_retry_count = 5;                  // attempts after the first when the queue is full
  bool deliver_error_frames = false;  // queue bus-off / restarted error frames at this endpoint
  bool notify_fd = false;  // create an eventfd that becomes readable when a frame is queued
};

class SimCanBus;

class SimCanEndpoint final : public CanBus {
 public:
  Status Send(const CanFrame& frame) override;
  Result<bool> Receive(CanFrame* frame, int timeout_ms) override;
  CanStats stats() const override;
  CanBusState state() const override;
  const char* name() const override { return name_; }

  // eventfd for poll()-based consumers (config.notify_fd), else -1. Readable while frames may be
  // pending; the consumer reads it (8 bytes) and then drains Receive(frame, 0).
  int notify_fd() const { return notify_fd_; }

  // The receive ring AddEndpoint() allocates for queue_depth frames.
  static constexpr size_t QueueBytes(size_t queue_depth) { return queue_depth * sizeof(CanFrame); }
  size_t queue_depth() const { return depth_; }

  SimCanEndpoint() = default;
  SimCanEndpoint(const SimCanEndpoint&) = delete;
  SimCanEndpoint& operator=(const SimCanEndpoint&) = delete;

 private:
  friend class SimCanBus;
  bool Accepts(const CanFrame& frame) const;  // filter check; bus mutex held
  void Enqueue(const CanFrame& frame);        // bus mutex held

  SimCanBus* bus_ = nullptr;
  char name_[kSimCanNameMax] = {};
  uint32_t filter_ids_[kSimCanMaxFilters] = {};
  size_t filter_count_ = 0;
  int tx_retry_count_ = 5;
  bool deliver_error_frames_ = false;
  int notify_fd_ = -1;

  std::unique_ptr<CanFrame[]> queue_;  // depth_ frames
  size_t depth_ = 0;
  size_t head_ = 0;
  size_t count_ = 0;
  std::condition_variable cv_;

  CanStats stats_;
  CanBusState state_ = CanBusState::kErrorActive;
  uint64_t tx_full_attempts_left_ = 0;
};

class SimCanBus {
 public:
  SimCanBus() = default;
  ~SimCanBus();
  SimCanBus(const SimCanBus&) = delete;
  SimCanBus& operator=(const SimCanBus&) = delete;

  // Claims one of the fixed endpoint slots. kResourceExhausted when all are taken.
  Result<SimCanEndpoint*> AddEndpoint(const SimCanEndpointConfig& config);

  // Fault injection (see the file comment).
  void InjectBusOff(SimCanEndpoint* endpoint);
  void RecoverFromBusOff(SimCanEndpoint* endpoint);
  void InjectTxQueueFull(SimCanEndpoint* endpoint, uint64_t attempts);
  // Moves an endpoint to error-warning / error-passive (or back to active) without bus-off.
  void InjectErrorState(SimCanEndpoint* endpoint, CanBusState state);

  // Frames that reached the medium (sent successfully by any endpoint).
  uint64_t frames_on_bus() const;

 private:
  friend class SimCanEndpoint;
  Status Transmit(SimCanEndpoint* sender, const CanFrame& frame);
  Result<bool> Receive(SimCanEndpoint* endpoint, CanFrame* frame, int timeout_ms);
  void QueueErrorFrame(SimCanEndpoint* endpoint, uint32_t error_class, uint8_t ctrl_bits);

  mutable std::mutex mutex_;
  SimCanEndpoint endpoints_[kSimCanMaxEndpoints];
  size_t endpoint_count_ = 0;
  uint64_t frames_on_bus_ = 0;
};

}  // namespace sh::hal
