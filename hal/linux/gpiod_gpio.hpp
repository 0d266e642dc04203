// GPIO backend on the Linux GPIO character device through libgpiod v1.6 (Debian 12, arm64).
// The trigger line is requested for rising-edge events (kernel-timestamped, queued in the
// kernel's event FIFO); outputs are requested as outputs with an initial inactive level.
// Active-low wiring is handled by libgpiod (GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW), so SetOutput
// always takes the logical level.
#pragma once

#include "hal/gpio.hpp"

struct gpiod_chip;
struct gpiod_line;

namespace sh::hal {

struct GpiodConfig {
  // Chip by name ("gpiochip0"), path ("/dev/gpiochip0"), label ("pinctrl-rp1") or number ("0"),
  // as gpiod_chip_open_lookup() accepts.
  const char* chip = "gpiochip0";
  int trigger_line = -1;  // line offsets on the chip; -1 = not wired
  int ready_line = -1;
  int busy_line = -1;
  int strobe_line = -1;
  bool trigger_active_low = false;
  bool outputs_active_low = false;
  bool trigger_pull_down = false;  // enable the SoC pull-down on the trigger (open collector PLCs)
  const char* consumer = "stereohash";  // shown by gpioinfo
};

class GpiodGpio final : public Gpio {
 public:
  GpiodGpio() = default;
  ~GpiodGpio() override { Close(); }
  GpiodGpio(const GpiodGpio&) = delete;
  GpiodGpio& operator=(const GpiodGpio&) = delete;

  // kNotFound: no such chip or line; kUnavailable: line busy or request refused;
  // kInvalidArgument: bad configuration.
  Status Open(const GpiodConfig& config);
  void Close();

  // kFailedPrecondition if no trigger line is configured.
  Result<bool> WaitTriggerRisingEdge(int timeout_ms, GpioEdgeEvent* event) override;
  // Outputs that are not wired (offset -1) accept the call and do nothing, so the firmware can
  // run on boards without a strobe output.
  Status SetOutput(GpioOutput output, bool active) override;

 private:
  gpiod_chip* chip_ = nullptr;
  gpiod_line* trigger_ = nullptr;
  gpiod_line* outputs_[kGpioOutputCount] = {};
};

}  // namespace sh::hal
