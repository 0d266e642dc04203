// Simulated GPIO: the simulator fires trigger edges, the firmware's output changes are recorded
// with timestamps so tests can check sequences (ready -> busy -> strobe ...).
// Fixed storage: kSimGpioTriggerQueueDepth pending edges (further edges are dropped and
// counted, as a real edge FIFO overflows) and the last kSimGpioOutputLogDepth output changes.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>

#include "hal/gpio.hpp"

namespace sh::hal {

inline constexpr size_t kSimGpioTriggerQueueDepth = 16;
inline constexpr size_t kSimGpioOutputLogDepth = 256;

struct GpioOutputChange {
  uint64_t timestamp_ns = 0;  // CLOCK_MONOTONIC
  GpioOutput output = GpioOutput::kReady;
  bool active = false;
};

class SimGpio final : public Gpio {
 public:
  Result<bool> WaitTriggerRisingEdge(int timeout_ms, GpioEdgeEvent* event) override;
  Status SetOutput(GpioOutput output, bool active) override;

  // Simulator side. timestamp_ns 0 = now. Returns false if the edge queue was full (dropped).
  bool FireTrigger(uint64_t timestamp_ns = 0);
  bool output(GpioOutput output) const;
  // Copies the recorded changes, oldest first, up to capacity; returns how many were copied.
  size_t CopyOutputLog(GpioOutputChange* out, size_t capacity) const;
  void ClearOutputLog();
  uint64_t triggers_dropped() const;
  uint64_t output_log_overwritten() const;  // oldest changes lost because the log was full

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  uint64_t edges_[kSimGpioTriggerQueueDepth] = {};
  size_t edge_head_ = 0, edge_count_ = 0;
  uint64_t triggers_dropped_ = 0;
  bool outputs_[kGpioOutputCount] = {};
  GpioOutputChange log_[kSimGpioOutputLogDepth];
  size_t log_head_ = 0, log_count_ = 0;
  uint64_t log_overwritten_ = 0;
};

}  // namespace sh::hal
