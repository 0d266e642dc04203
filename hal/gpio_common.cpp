#include <time.h>

#include "hal/gpio.hpp"

namespace sh::hal {

const char* GpioOutputName(GpioOutput output) {
  switch (output) {
    case GpioOutput::kReady:
      return "ready";
    case GpioOutput::kBusy:
      return "busy";
    case GpioOutput::kStrobe:
      return "strobe";
  }
  return "unknown";
}

uint64_t GpioNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000000u + static_cast<uint64_t>(ts.tv_nsec);
}

}  // namespace sh::hal
