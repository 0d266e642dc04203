#include "hal/linux/gpiod_gpio.hpp"

#include <errno.h>
#include <gpiod.h>
#include <time.h>

#include <cstring>

namespace sh::hal {

Status GpiodGpio::Open(const GpiodConfig& config) {
  Close();
  if (config.chip == nullptr || config.consumer == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "gpiod: chip and consumer must be set");
  }
  chip_ = gpiod_chip_open_lookup(config.chip);
  if (chip_ == nullptr) {
    return Status::Error(StatusCode::kNotFound, "gpiod: cannot open GPIO chip '%s': %s",
                         config.chip, std::strerror(errno));
  }
  const unsigned num_lines = gpiod_chip_num_lines(chip_);
  auto get_line = [&](int offset, const char* role, gpiod_line** line) -> Status {
    if (offset < 0) return Status::Ok();
    if (static_cast<unsigned>(offset) >= num_lines) {
      return Status::Error(StatusCode::kNotFound, "gpiod: %s line %d not on '%s' (%u lines)", role,
                           offset, config.chip, num_lines);
    }
    *line = gpiod_chip_get_line(chip_, static_cast<unsigned>(offset));
    if (*line == nullptr) {
      return Status::Error(StatusCode::kNotFound, "gpiod: %s line %d on '%s': %s", role, offset,
                           config.chip, std::strerror(errno));
    }
    return Status::Ok();
  };

  Status s = get_line(config.trigger_line, "trigger", &trigger_);
  if (s.ok() && trigger_ != nullptr) {
    int flags = 0;
    if (config.trigger_active_low) flags |= GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW;
    if (config.trigger_pull_down) flags |= GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
    if (gpiod_line_request_rising_edge_events_flags(trigger_, config.consumer, flags) != 0) {
      s = Status::Error(StatusCode::kUnavailable,
                        "gpiod: cannot request trigger line %d for rising edges: %s",
                        config.trigger_line, std::strerror(errno));
      trigger_ = nullptr;
    }
  }
  const int offsets[kGpioOutputCount] = {config.ready_line, config.busy_line, config.strobe_line};
  for (size_t i = 0; s.ok() && i < kGpioOutputCount; ++i) {
    const char* role = GpioOutputName(static_cast<GpioOutput>(i));
    s = get_line(offsets[i], role, &outputs_[i]);
    if (!s.ok() || outputs_[i] == nullptr) continue;
    const int flags = config.outputs_active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
    if (gpiod_line_request_output_flags(outputs_[i], config.consumer, flags, 0) != 0) {
      s = Status::Error(StatusCode::kUnavailable, "gpiod: cannot request %s line %d as output: %s",
                        role, offsets[i], std::strerror(errno));
      outputs_[i] = nullptr;
    }
  }
  if (!s.ok()) Close();
  return s;
}

void GpiodGpio::Close() {
  if (chip_ == nullptr) return;
  // Closing the chip releases every line requested from it.
  gpiod_chip_close(chip_);
  chip_ = nullptr;
  trigger_ = nullptr;
  for (gpiod_line*& line : outputs_) line = nullptr;
}

Result<bool> GpiodGpio::WaitTriggerRisingEdge(int timeout_ms, GpioEdgeEvent* event) {
  if (trigger_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "gpiod: no trigger line configured");
  }
  if (event == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "gpiod: WaitTriggerRisingEdge needs an event");
  }
  timespec timeout{};
  timespec* timeout_ptr = nullptr;
  if (timeout_ms >= 0) {
    timeout.tv_sec = timeout_ms / 1000;
    timeout.tv_nsec = static_cast<long>(timeout_ms % 1000) * 1000000L;
    timeout_ptr = &timeout;
  }
  for (;;) {
    // libgpiod v1 waits forever when given a null timeout.
    const int ready = gpiod_line_event_wait(trigger_, timeout_ptr);
    if (ready < 0) {
      if (errno == EINTR) continue;
      return Status::Error(StatusCode::kUnavailable, "gpiod: waiting for trigger: %s",
                           std::strerror(errno));
    }
    if (ready == 0) return false;
    gpiod_line_event ev{};
    if (gpiod_line_event_read(trigger_, &ev) != 0) {
      return Status::Error(StatusCode::kUnavailable, "gpiod: reading trigger event: %s",
                           std::strerror(errno));
    }
    // Only rising edges are requested; anything else would be a kernel/driver surprise.
    if (ev.event_type != GPIOD_LINE_EVENT_RISING_EDGE) continue;
    event->timestamp_ns =
        static_cast<uint64_t>(ev.ts.tv_sec) * 1000000000u + static_cast<uint64_t>(ev.ts.tv_nsec);
    return true;
  }
}

Status GpiodGpio::SetOutput(GpioOutput output, bool active) {
  const size_t index = static_cast<size_t>(output);
  if (index >= kGpioOutputCount) {
    return Status::Error(StatusCode::kInvalidArgument, "gpiod: output %zu does not exist", index);
  }
  if (chip_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "gpiod: SetOutput() before Open()");
  }
  if (outputs_[index] == nullptr) return Status::Ok();  // not wired on this board
  if (gpiod_line_set_value(outputs_[index], active ? 1 : 0) != 0) {
    return Status::Error(StatusCode::kUnavailable, "gpiod: setting %s: %s", GpioOutputName(output),
                         std::strerror(errno));
  }
  return Status::Ok();
}

}  // namespace sh::hal
