#include "firmware/can_health.hpp"

#include "firmware/firmware_core.hpp"

namespace sh::fw {
namespace {

uint32_t Saturate(uint64_t v) { return v > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<uint32_t>(v); }

}  // namespace

CanHealthMonitor::Actions CanHealthMonitor::Step(hal::CanBusState bus, const hal::CanStats& now,
                                                 uint32_t faults) {
  using protocol::EmcyCode;
  Actions out;
  auto add = [&out](Kind kind, uint32_t condition, EmcyCode code, uint32_t detail) {
    out.action[out.count++] = {kind, condition, code, detail};
  };
  const bool bus_off = bus == hal::CanBusState::kBusOff;
  if ((faults & kFaultCanBusOff) && !bus_off && !bus_off_reported_) {
    // The fault condition starts now, as its EMCY can be sent; clear-fault ends it.
    bus_off_reported_ = true;
    add(Kind::kRaise, kFaultCanBusOff, EmcyCode::kRecoveredFromBusOff,
        Saturate(now.bus_off_events));
  }
  if (!(faults & kFaultCanBusOff)) bus_off_reported_ = false;
  if (bus == hal::CanBusState::kErrorPassive && !passive_reported_) {
    passive_reported_ = true;
    add(Kind::kRaise, kWarningCanErrorPassive, EmcyCode::kCanErrorPassive, 0);
  }
  if (bus == hal::CanBusState::kErrorActive && passive_reported_) {
    passive_reported_ = false;
    add(Kind::kClear, kWarningCanErrorPassive, EmcyCode::kNoError, 0);
  }
  if ((faults & kFaultCanTxDropped) && !tx_drop_reported_ && !bus_off) {
    tx_drop_reported_ = true;
    add(Kind::kRaise, kFaultCanTxDropped, EmcyCode::kCommunication,
        Saturate(now.tx_dropped_queue_full));
  }
  if (!(faults & kFaultCanTxDropped)) tx_drop_reported_ = false;
  if (now.rx_dropped_overflow > last_.rx_dropped_overflow) {
    add(Kind::kEvent, 0, EmcyCode::kCanOverrun,
        Saturate(now.rx_dropped_overflow - last_.rx_dropped_overflow));
  }
  last_ = now;
  return out;
}

}  // namespace sh::fw
