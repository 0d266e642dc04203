#include "hal/sim/can_sim_bus.hpp"

#include <sys/eventfd.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <new>

namespace sh::hal {
namespace {

// linux/can/error.h error classes, repeated so the simulator needs no CAN kernel headers.
constexpr uint32_t kErrCrtl = 0x04;
constexpr uint32_t kErrBusOff = 0x40;
constexpr uint32_t kErrRestarted = 0x100;
constexpr uint8_t kErrCrtlWarning = 0x04 | 0x08;
constexpr uint8_t kErrCrtlPassive = 0x10 | 0x20;
constexpr uint8_t kErrCrtlActive = 0x40;

void Notify(int fd) {
  if (fd < 0) return;
  const uint64_t one = 1;
  // A full eventfd counter (never in practice) only means the reader is already woken.
  [[maybe_unused]] const ssize_t n = write(fd, &one, sizeof(one));
}

}  // namespace

SimCanBus::~SimCanBus() {
  for (size_t i = 0; i < endpoint_count_; ++i) {
    if (endpoints_[i].notify_fd_ >= 0) close(endpoints_[i].notify_fd_);
  }
}

Result<SimCanEndpoint*> SimCanBus::AddEndpoint(const SimCanEndpointConfig& config) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (endpoint_count_ == kSimCanMaxEndpoints) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "sim CAN bus: all %zu endpoints are in use", kSimCanMaxEndpoints);
  }
  if (config.filter_count > kSimCanMaxFilters) {
    return Status::Error(StatusCode::kInvalidArgument, "sim CAN bus: %zu filters, at most %zu",
                         config.filter_count, kSimCanMaxFilters);
  }
  if (config.tx_retry_count < 0) {
    return Status::Error(StatusCode::kInvalidArgument, "sim CAN bus: negative retry count");
  }
  if (config.queue_depth < 1 || config.queue_depth > kSimCanMaxQueueDepth) {
    return Status::Error(StatusCode::kOutOfRange, "sim CAN bus: queue depth %zu, 1..%zu",
                         config.queue_depth, kSimCanMaxQueueDepth);
  }
  SimCanEndpoint& e = endpoints_[endpoint_count_];
  // The ring of the configured depth, once per endpoint (never per frame).
  e.queue_.reset(new (std::nothrow) CanFrame[config.queue_depth]);
  if (e.queue_ == nullptr) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "sim CAN bus: cannot allocate a queue of %zu frames", config.queue_depth);
  }
  if (config.notify_fd) {
    e.notify_fd_ = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (e.notify_fd_ < 0) {
      return Status::Error(StatusCode::kUnavailable, "sim CAN bus: eventfd: %s",
                           std::strerror(errno));
    }
  }
  ++endpoint_count_;
  e.bus_ = this;
  std::snprintf(e.name_, sizeof(e.name_), "%s", config.name != nullptr ? config.name : "sim");
  for (size_t i = 0; i < config.filter_count; ++i) e.filter_ids_[i] = config.filter_ids[i];
  e.filter_count_ = config.filter_count;
  e.tx_retry_count_ = config.tx_retry_count;
  e.depth_ = config.queue_depth;
  e.deliver_error_frames_ = config.deliver_error_frames;
  return &e;
}

bool SimCanEndpoint::Accepts(const CanFrame& frame) const {
  if (frame.error) return deliver_error_frames_;
  if (filter_count_ == 0) return true;
  for (size_t i = 0; i < filter_count_; ++i) {
    if (!frame.extended && !frame.rtr && filter_ids_[i] == frame.id) return true;
  }
  return false;
}

void SimCanEndpoint::Enqueue(const CanFrame& frame) {
  if (count_ == depth_) {
    ++stats_.rx_dropped_overflow;
    return;
  }
  queue_[(head_ + count_) % depth_] = frame;
  ++count_;
  cv_.notify_one();
  Notify(notify_fd_);
}

Status SimCanBus::Transmit(SimCanEndpoint* sender, const CanFrame& frame) {
  SH_RETURN_IF_ERROR(ValidateCanFrame(frame));
  std::lock_guard<std::mutex> lock(mutex_);
  if (sender->state_ == CanBusState::kBusOff) {
    return Status::Error(StatusCode::kUnavailable,
                         "sim CAN %s is bus-off; frame 0x%X not sent (restart needed)",
                         sender->name_, frame.id);
  }
  // Each attempt that finds the queue full costs one retry, as with ENOBUFS on SocketCAN.
  for (int attempt = 0; sender->tx_full_attempts_left_ > 0; ++attempt) {
    --sender->tx_full_attempts_left_;
    if (attempt >= sender->tx_retry_count_) {
      ++sender->stats_.tx_dropped_queue_full;
      return Status::Error(StatusCode::kResourceExhausted,
                           "sim CAN %s transmit queue full; frame 0x%X dropped after %d retries",
                           sender->name_, frame.id, sender->tx_retry_count_);
    }
    ++sender->stats_.tx_retries;
  }
  CanFrame stamped = frame;
  stamped.timestamp_us = frame.timestamp_us != 0 ? frame.timestamp_us : CanNowUs();
  ++sender->stats_.tx_frames;
  ++frames_on_bus_;
  for (size_t i = 0; i < endpoint_count_; ++i) {
    SimCanEndpoint& e = endpoints_[i];
    if (&e == sender || !e.Accepts(stamped)) continue;
    e.Enqueue(stamped);
  }
  return Status::Ok();
}

Result<bool> SimCanBus::Receive(SimCanEndpoint* e, CanFrame* frame, int timeout_ms) {
  if (frame == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "sim CAN: Receive() needs a frame");
  }
  std::unique_lock<std::mutex> lock(mutex_);
  auto has_frame = [e] { return e->count_ > 0; };
  if (timeout_ms < 0) {
    e->cv_.wait(lock, has_frame);
  } else if (!e->cv_.wait_for(lock, std::chrono::milliseconds(timeout_ms), has_frame)) {
    return false;
  }
  *frame = e->queue_[e->head_];
  e->head_ = (e->head_ + 1) % e->depth_;
  --e->count_;
  if (frame->error) {
    ++e->stats_.error_frames;
  } else {
    ++e->stats_.rx_frames;
  }
  return true;
}

void SimCanBus::QueueErrorFrame(SimCanEndpoint* e, uint32_t error_class, uint8_t ctrl_bits) {
  if (!e->deliver_error_frames_) {
    ++e->stats_.error_frames;  // seen by the controller even if not delivered
    return;
  }
  CanFrame f;
  f.error = true;
  f.id = error_class;
  f.len = kCanMaxDataBytes;
  f.data[1] = ctrl_bits;
  f.timestamp_us = CanNowUs();
  e->Enqueue(f);
}

void SimCanBus::InjectBusOff(SimCanEndpoint* e) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (e->state_ == CanBusState::kBusOff) return;
  e->state_ = CanBusState::kBusOff;
  ++e->stats_.bus_off_events;
  QueueErrorFrame(e, kErrBusOff, 0);
}

void SimCanBus::RecoverFromBusOff(SimCanEndpoint* e) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (e->state_ != CanBusState::kBusOff) return;
  e->state_ = CanBusState::kErrorActive;
  QueueErrorFrame(e, kErrRestarted, 0);
}

void SimCanBus::InjectTxQueueFull(SimCanEndpoint* e, uint64_t attempts) {
  std::lock_guard<std::mutex> lock(mutex_);
  e->tx_full_attempts_left_ = attempts;
}

void SimCanBus::InjectErrorState(SimCanEndpoint* e, CanBusState state) {
  if (state == CanBusState::kBusOff) {
    InjectBusOff(e);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  e->state_ = state;
  const uint8_t bits = state == CanBusState::kErrorPassive   ? kErrCrtlPassive
                       : state == CanBusState::kErrorWarning ? kErrCrtlWarning
                                                             : kErrCrtlActive;
  QueueErrorFrame(e, kErrCrtl, bits);
}

uint64_t SimCanBus::frames_on_bus() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_on_bus_;
}

Status SimCanEndpoint::Send(const CanFrame& frame) {
  if (bus_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "sim CAN endpoint is not on a bus");
  }
  return bus_->Transmit(this, frame);
}

Result<bool> SimCanEndpoint::Receive(CanFrame* frame, int timeout_ms) {
  if (bus_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "sim CAN endpoint is not on a bus");
  }
  return bus_->Receive(this, frame, timeout_ms);
}

CanStats SimCanEndpoint::stats() const {
  if (bus_ == nullptr) return stats_;
  std::lock_guard<std::mutex> lock(bus_->mutex_);
  return stats_;
}

CanBusState SimCanEndpoint::state() const {
  if (bus_ == nullptr) return state_;
  std::lock_guard<std::mutex> lock(bus_->mutex_);
  return state_;
}

}  // namespace sh::hal
