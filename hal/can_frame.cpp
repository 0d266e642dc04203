#include <time.h>

#include "hal/can.hpp"

namespace sh::hal {

const char* CanBusStateName(CanBusState state) {
  switch (state) {
    case CanBusState::kErrorActive:
      return "error-active";
    case CanBusState::kErrorWarning:
      return "error-warning";
    case CanBusState::kErrorPassive:
      return "error-passive";
    case CanBusState::kBusOff:
      return "bus-off";
  }
  return "unknown";
}

Status ValidateCanFrame(const CanFrame& frame) {
  if (frame.error) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "CAN frame 0x%X is an error frame; error frames cannot be sent", frame.id);
  }
  const uint32_t id_max = frame.extended ? kCanExtendedIdMax : kCanStandardIdMax;
  if (frame.id > id_max) {
    return Status::Error(StatusCode::kInvalidArgument, "CAN id 0x%X exceeds the %s maximum 0x%X",
                         frame.id, frame.extended ? "29-bit" : "11-bit", id_max);
  }
  if (frame.len > kCanMaxDataBytes) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "CAN frame 0x%X has %u data bytes; classic CAN allows at most 8", frame.id,
                         frame.len);
  }
  return Status::Ok();
}

uint64_t CanNowUs() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000u + static_cast<uint64_t>(ts.tv_nsec) / 1000u;
}

}  // namespace sh::hal
