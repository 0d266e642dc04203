// Digital I/O of the vision board: one trigger input (the PLC or a light barrier requests a
// recognition with a rising edge) and three outputs towards the PLC / illumination.
//   ready  - the device is operational and waits for a trigger
//   busy   - a recognition is running (trigger edges are still timestamped and queued)
//   strobe - illumination / projector enable during exposure
// Backends: hal/linux/gpiod_gpio (libgpiod v1.6 character device) and hal/sim/gpio_sim.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::hal {

struct GpioEdgeEvent {
  // Time of the edge on CLOCK_MONOTONIC in nanoseconds (the kernel's line event clock since
  // Linux 5.7; earlier kernels used CLOCK_REALTIME).
  uint64_t timestamp_ns = 0;
};

enum class GpioOutput : uint8_t { kReady = 0, kBusy = 1, kStrobe = 2 };
inline constexpr size_t kGpioOutputCount = 3;
const char* GpioOutputName(GpioOutput output);

class Gpio {
 public:
  virtual ~Gpio() = default;

  // Waits up to timeout_ms (0 = poll, < 0 = forever) for a rising edge on the trigger input.
  // true: *event holds the edge; false: timeout. Edges that arrive while nobody waits are
  // queued (bounded by the backend) and returned by later calls in order.
  virtual Result<bool> WaitTriggerRisingEdge(int timeout_ms, GpioEdgeEvent* event) = 0;

  // Drives an output; `active` is the logical level (active-low wiring is a backend setting).
  virtual Status SetOutput(GpioOutput output, bool active) = 0;
};

// CLOCK_MONOTONIC in nanoseconds, the time base of GpioEdgeEvent.
uint64_t GpioNowNs();

}  // namespace sh::hal
