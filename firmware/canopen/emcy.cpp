#include "firmware/canopen/emcy.hpp"

#include <cstdint>

#include "firmware/le_bytes.hpp"

namespace sh::protocol {

uint8_t ErrorRegisterFor(uint16_t error_code) {
  if (error_code == 0) return 0;
  uint8_t reg = 0x01;  // generic error: set whenever any error is present
  const uint16_t group = error_code & 0xF000;
  if (group == 0x8000) reg |= 0x10;
  if (group == 0x5000 || group == 0x6000 || group == 0x7000 || (error_code & 0xFF00) == 0xFF00) {
    reg |= 0x80;
  }
  return reg;
}

Result<CanFrame> EncodeEmcy(const Emcy& emcy, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  CanFrame f = MakeFrame(kCobEmcy + node_id, 8);
  PutU16(&f.data[0], emcy.error_code);
  f.data[2] = emcy.error_register;
  f.data[3] = static_cast<uint8_t>(emcy.state);
  PutU32(&f.data[4], emcy.detail);
  return f;
}

Result<Emcy> DecodeEmcy(const CanFrame& frame, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckId(frame, kCobEmcy + node_id, "EMCY"));
  if (frame.len != 8) {
    return Status::Error(StatusCode::kInvalidArgument, "EMCY has %u bytes, expected 8", frame.len);
  }
  if (frame.data[3] > static_cast<uint8_t>(FirmwareState::kFault)) {
    return Status::Error(StatusCode::kInvalidArgument, "EMCY firmware state %u unknown",
                         frame.data[3]);
  }
  Emcy e;
  e.error_code = GetU16(&frame.data[0]);
  e.error_register = frame.data[2];
  e.state = static_cast<FirmwareState>(frame.data[3]);
  e.detail = GetU32(&frame.data[4]);
  return e;
}

}  // namespace sh::protocol
