// Interpretation of SocketCAN error frames (linux/can/error.h) as a controller state machine.
// Kept apart from the socket code so it can be tested on kernels without AF_CAN.
#pragma once

#include <cstdint>

#include "hal/can.hpp"

namespace sh::hal {

struct CanErrorUpdate {
  CanBusState state = CanBusState::kErrorActive;  // state after the error frame
  bool entered_bus_off = false;                   // transition into bus-off (count it once)
  bool restarted = false;                         // controller restarted after bus-off
  bool controller_overflow = false;               // CAN_ERR_CRTL_RX/TX_OVERFLOW reported
};

// error_class: can_id of the error frame without CAN_ERR_FLAG; data: its 8 data bytes
// (data[1] holds the CAN_ERR_CRTL_* bits when CAN_ERR_CRTL is set).
CanErrorUpdate ApplyCanErrorFrame(CanBusState current, uint32_t error_class,
                                  const uint8_t data[kCanMaxDataBytes]);

// The error classes the socketcan backend subscribes to with CAN_RAW_ERR_FILTER.
uint32_t SocketCanErrorMask();

}  // namespace sh::hal
