#include "hal/linux/socketcan_errors.hpp"

#include <linux/can.h>
#include <linux/can/error.h>

namespace sh::hal {

uint32_t SocketCanErrorMask() {
  // Bus-off and restart drive the state machine; controller reports carry warning/passive
  // levels and overflows; TX timeout and no-ACK are the typical symptoms of a missing peer.
  return CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_RESTARTED | CAN_ERR_TX_TIMEOUT | CAN_ERR_ACK;
}

CanErrorUpdate ApplyCanErrorFrame(CanBusState current, uint32_t error_class,
                                  const uint8_t data[kCanMaxDataBytes]) {
  CanErrorUpdate update;
  update.state = current;
  if (error_class & CAN_ERR_CRTL) {
    const uint8_t crtl = data[1];
    if (crtl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) {
      update.controller_overflow = true;
    }
    // The most severe level reported wins; ACTIVE is the kernel's "recovered" notification.
    if (crtl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
      update.state = CanBusState::kErrorPassive;
    } else if (crtl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
      update.state = CanBusState::kErrorWarning;
    } else if (crtl & CAN_ERR_CRTL_ACTIVE) {
      update.state = CanBusState::kErrorActive;
    }
  }
  if (error_class & CAN_ERR_RESTARTED) {
    update.restarted = true;
    update.state = CanBusState::kErrorActive;
  }
  // Checked last: a frame reporting both restart and bus-off means the controller went off again.
  if (error_class & CAN_ERR_BUSOFF) {
    update.entered_bus_off = current != CanBusState::kBusOff;
    update.state = CanBusState::kBusOff;
  }
  return update;
}

}  // namespace sh::hal
