#include "hal/sim/gpio_sim.hpp"

#include <chrono>

namespace sh::hal {

Result<bool> SimGpio::WaitTriggerRisingEdge(int timeout_ms, GpioEdgeEvent* event) {
  if (event == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "sim GPIO: WaitTriggerRisingEdge needs an event");
  }
  std::unique_lock<std::mutex> lock(mutex_);
  auto pending = [this] { return edge_count_ > 0; };
  if (timeout_ms < 0) {
    cv_.wait(lock, pending);
  } else if (!cv_.wait_for(lock, std::chrono::milliseconds(timeout_ms), pending)) {
    return false;
  }
  event->timestamp_ns = edges_[edge_head_];
  edge_head_ = (edge_head_ + 1) % kSimGpioTriggerQueueDepth;
  --edge_count_;
  return true;
}

Status SimGpio::SetOutput(GpioOutput output, bool active) {
  const size_t index = static_cast<size_t>(output);
  if (index >= kGpioOutputCount) {
    return Status::Error(StatusCode::kInvalidArgument, "sim GPIO: output %zu does not exist",
                         index);
  }
  std::lock_guard<std::mutex> lock(mutex_);
  outputs_[index] = active;
  GpioOutputChange change;
  change.timestamp_ns = GpioNowNs();
  change.output = output;
  change.active = active;
  // Ring buffer: keep the newest changes, count what falls out.
  if (log_count_ == kSimGpioOutputLogDepth) {
    log_head_ = (log_head_ + 1) % kSimGpioOutputLogDepth;
    --log_count_;
    ++log_overwritten_;
  }
  log_[(log_head_ + log_count_) % kSimGpioOutputLogDepth] = change;
  ++log_count_;
  return Status::Ok();
}

bool SimGpio::FireTrigger(uint64_t timestamp_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (edge_count_ == kSimGpioTriggerQueueDepth) {
    ++triggers_dropped_;
    return false;
  }
  edges_[(edge_head_ + edge_count_) % kSimGpioTriggerQueueDepth] =
      timestamp_ns != 0 ? timestamp_ns : GpioNowNs();
  ++edge_count_;
  cv_.notify_one();
  return true;
}

bool SimGpio::output(GpioOutput output) const {
  const size_t index = static_cast<size_t>(output);
  std::lock_guard<std::mutex> lock(mutex_);
  return index < kGpioOutputCount && outputs_[index];
}

size_t SimGpio::CopyOutputLog(GpioOutputChange* out, size_t capacity) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t n = log_count_ < capacity ? log_count_ : capacity;
  for (size_t i = 0; i < n; ++i) out[i] = log_[(log_head_ + i) % kSimGpioOutputLogDepth];
  return n;
}

void SimGpio::ClearOutputLog() {
  std::lock_guard<std::mutex> lock(mutex_);
  log_head_ = log_count_ = 0;
}

uint64_t SimGpio::triggers_dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return triggers_dropped_;
}

uint64_t SimGpio::output_log_overwritten() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return log_overwritten_;
}

}  // namespace sh::hal
