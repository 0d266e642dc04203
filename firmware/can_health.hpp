// CAN health as the heartbeat thread sees it once per period: the controller's state, its
// counters and the core's fault bits, turned into the EMCYs a PLC should get, each once per
// episode. Pure (no bus, no threads, no clock), so every sequence is tested directly
// (tests/firmware/can_health_test.cpp).
//
//   bus-off            fault bit set (by the core); the condition starts with EMCY 0x8140 once
//                      the controller is back, as nothing can be sent while it is off
//   error passive      warning condition with EMCY 0x8120, ended (error reset) only after the
//                      controller was error-active again
//   frames dropped     (transmit queue full) fault condition with EMCY 0x8100 once per fault,
//                      not while bus-off
//   receive overrun    an event (EMCY 0x8110 and its reset) with the frames lost since the
//                      last period
#pragma once

#include <cstdint>

#include "firmware/canopen/emcy.hpp"
#include "hal/can.hpp"

namespace sh::fw {

class CanHealthMonitor {
 public:
  // What the core does with an action: kRaise starts the error condition `condition` (a
  // FaultBits or WarningBits bit) with its EMCY, kClear ends it (error reset), kEvent is an EMCY
  // without lasting cause.
  enum class Kind : uint8_t { kRaise, kClear, kEvent };
  struct Action {
    Kind kind = Kind::kEvent;
    uint32_t condition = 0;
    protocol::EmcyCode code = protocol::EmcyCode::kNoError;
    uint32_t detail = 0;
  };
  struct Actions {
    Action action[4];  // at most one per condition above, in that order
    int count = 0;
  };

  explicit CanHealthMonitor(const hal::CanStats& initial) : last_(initial) {}

  // One period: `faults` are the core's fault bits (kFaultCanBusOff, kFaultCanTxDropped of
  // firmware_core.hpp) after it marked a bus-off it saw.
  Actions Step(hal::CanBusState bus, const hal::CanStats& now, uint32_t faults);

 private:
  hal::CanStats last_;
  bool bus_off_reported_ = false;  // the bus-off fault was seen; its condition was raised
  bool passive_reported_ = false;  // the error-passive warning is active
  bool tx_drop_reported_ = false;
};

}  // namespace sh::fw
