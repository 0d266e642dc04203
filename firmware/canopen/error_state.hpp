// Error register (0x1001), pre-defined error field (0x1003) and the EMCY sequence of CiA 301
// 7.2.7, kept in step with the device's error conditions:
//  - a condition that becomes active sends its EMCY with the register including it;
//  - a condition that clears sends EMCY 0x0000 ("error reset") with the register of the
//    conditions still active, so a manager's diagnostics leave "in error" when the last clears;
//  - an event without lasting cause (a rejected command, skipped camera frames) sends its EMCY
//    and at once the error reset, since nothing remains in error.
// Conditions are identified by bits (the firmware's fault causes and warnings). Each EMCY that
// is not a reset is also pushed into 0x1003 (newest at sub 1; error code in the low word, the
// low 16 bits of the detail in the high word). Pure and thread-free.
#pragma once

#include <cstdint>

#include "firmware/canopen/object_dictionary.hpp"

namespace sh::canopen {

struct EmcyMessage {
  uint16_t code = 0;
  uint8_t error_register = 0;
  uint32_t detail = 0;
};

class ErrorState {
 public:
  explicit ErrorState(ObjectDictionary* od) : od_(od) {}

  // Condition `bit` (one bit) is active with `code`: the EMCY to send.
  EmcyMessage Raise(uint32_t bit, uint16_t code, uint32_t detail);
  // Condition `bit` cleared: true with the error reset to send if it was active.
  bool Clear(uint32_t bit, EmcyMessage* reset);
  // Clears every condition in `bits`: true with one error reset if any was active.
  bool ClearAll(uint32_t bits, EmcyMessage* reset);
  // A transient error: its EMCY, then the error reset.
  void Event(uint16_t code, uint32_t detail, EmcyMessage* error, EmcyMessage* reset);

  uint32_t active() const { return active_; }
  uint8_t error_register() const { return RegisterOf(active_); }
  // 0x1003 sub 0 written from the bus: 0 clears the history, anything else is refused.
  SdoAbort WriteHistoryCount(uint32_t value);

 private:
  uint8_t RegisterOf(uint32_t conditions) const;
  void Push(uint16_t code, uint32_t detail);
  void Publish();  // 0x1001 from the active conditions

  ObjectDictionary* od_;
  uint32_t active_ = 0;
  uint16_t codes_[32] = {};  // EMCY code of each active condition bit
};

}  // namespace sh::canopen
