// EMCY (0x080 + id), 8 bytes: [error code u16, error register u8, firmware state u8, detail u32]
// (CiA 301 emergency object; bytes 3..7 are the manufacturer-specific part).
#pragma once

#include <cstdint>

#include "firmware/canopen/cob_id.hpp"
#include "recog/base/status.hpp"

namespace sh::protocol {

enum class EmcyCode : uint16_t {
  kNoError = 0x0000,  // sent after a fault is cleared (CANopen "error reset")
  kGeneric = 0x1000,
  kDeviceHardware = 0x5000,  // board fault (GPIO, memory)
  kSoftware = 0x6100,        // internal software error
  kDataSet = 0x6300,         // model tables missing or corrupt
  kSensor = 0x7300,          // camera: no frames, timeout, sync lost
  kCommunication = 0x8100,   // generic CAN communication problem
  kCanOverrun = 0x8110,      // received frames lost
  kCanErrorPassive = 0x8120,
  kRecoveredFromBusOff = 0x8140,
  kProtocolError = 0x8200,   // command rejected: unknown code or value out of range
  kPdoLengthError = 0x8210,  // command frame too short
  kRecording = 0xFF10,       // manufacturer-specific: a recorded pair could not be written
};

// The firmware's state, as EMCY byte 3 and the dictionary's device status carry it.
enum class FirmwareState : uint8_t {
  kInit = 0,
  kReady = 1,
  kBusy = 2,
  kFault = 3,
};

struct Emcy {
  uint16_t error_code = 0;
  uint8_t error_register = 0;  // CiA 301 object 0x1001 bits; ErrorRegisterFor() derives it
  FirmwareState state = FirmwareState::kInit;
  uint32_t detail = 0;  // manufacturer-specific, see MakeCommandRejectedEmcy (command_codec.hpp)
};

// CiA 301 error register: bit 0 generic (any error), bit 4 communication (0x8xxx),
// bit 7 manufacturer-specific (0x5000, 0x6xxx, 0x7xxx, 0xFFxx). 0 for kNoError.
uint8_t ErrorRegisterFor(uint16_t error_code);
Result<CanFrame> EncodeEmcy(const Emcy& emcy, uint8_t node_id);
Result<Emcy> DecodeEmcy(const CanFrame& frame, uint8_t node_id);

}  // namespace sh::protocol
