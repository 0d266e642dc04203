// CAN bus interface shared by the board backend (hal/linux/socketcan_bus) and the simulator
// (hal/sim/can_sim_bus). Classic CAN only: at most 8 data bytes per frame.
//
// Backends never allocate after Open()/construction: queues are fixed-size arrays and a full
// queue is reported through Status and counted in CanStats, never grown.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"

namespace sh::hal {

inline constexpr uint32_t kCanStandardIdMax = 0x7FF;       // 11-bit identifier
inline constexpr uint32_t kCanExtendedIdMax = 0x1FFFFFFF;  // 29-bit identifier
inline constexpr uint8_t kCanMaxDataBytes = 8;

struct CanFrame {
  uint32_t id = 0;  // 11-bit (extended = false) or 29-bit; for error frames the CAN_ERR_* class
  uint8_t len = 0;  // 0..8 data bytes (the DLC of a classic frame)
  uint8_t data[kCanMaxDataBytes] = {};
  bool extended = false;
  bool rtr = false;    // remote transmission request (no data)
  bool error = false;  // controller error report (SocketCAN error frame), never transmitted
  // Time the frame was received or handed to the bus, microseconds since the Unix epoch
  // (CLOCK_REALTIME, like candump). 0 means "stamp it now" when passed to Send().
  uint64_t timestamp_us = 0;
};

// Counters since Open(); monotonic, never reset by the backend.
struct CanStats {
  uint64_t tx_frames = 0;              // frames accepted by the driver/bus
  uint64_t rx_frames = 0;              // data frames delivered to Receive()
  uint64_t tx_retries = 0;             // waits for room in a full transmit queue
  uint64_t tx_dropped_queue_full = 0;  // frames given up after the bounded retries
  uint64_t rx_dropped_overflow = 0;    // frames lost because a receive queue was full
  uint64_t bus_off_events = 0;         // transitions into bus-off
  uint64_t error_frames = 0;           // controller error reports seen
};

// Fault confinement state of the controller (ISO 11898-1).
enum class CanBusState : uint8_t { kErrorActive, kErrorWarning, kErrorPassive, kBusOff };
const char* CanBusStateName(CanBusState state);

class CanBus {
 public:
  virtual ~CanBus() = default;

  // Queues one frame for transmission. Errors: kInvalidArgument (bad id/len/flags),
  // kResourceExhausted (transmit queue stayed full through the bounded retries; counted in
  // tx_dropped_queue_full), kUnavailable (bus-off or interface down).
  virtual Status Send(const CanFrame& frame) = 0;

  // Waits up to timeout_ms (0 = poll, < 0 = forever) for a frame. true: *frame is filled;
  // false: timeout. Error frames are returned only if the backend was configured to deliver
  // them; otherwise they update state() and stats() silently.
  virtual Result<bool> Receive(CanFrame* frame, int timeout_ms) = 0;

  virtual CanStats stats() const = 0;
  virtual CanBusState state() const = 0;
  // Interface name used in logs, e.g. "can0".
  virtual const char* name() const = 0;
};

// Checks id range, length and flag combinations; the message names the offending field.
Status ValidateCanFrame(const CanFrame& frame);

// Current CLOCK_REALTIME in microseconds, the timestamp base of CanFrame.
uint64_t CanNowUs();

}  // namespace sh::hal
