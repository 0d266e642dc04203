// Identifiers of the CAN protocol between the vision board and the PLC (docs/can-protocol.md has
// the frame tables; firmware/stereohash.dbc describes the same frames for CAN tools), and the
// checks every frame codec makes on node ids and received identifiers.
//
// CANopen-compatible identifiers from the predefined connection set: COB-ID = function code +
// node id (1..127). All multi-byte fields are little-endian (CANopen byte order).
//
//   0x000        NMT command        controller -> device   (start/stop/pre-op/reset)
//   0x080 + id   EMCY               device -> controller   (error code, register, state, detail)
//   0x180 + id   result header      device -> controller   (TPDO1)
//   0x200 + id   command            controller -> device   (RPDO1)
//   0x280 + id   result object part device -> controller   (TPDO2, multiplexed: 4 parts/object)
//   0x380 + id   result end         device -> controller   (TPDO3, count + CRC-8 of the set)
//   0x480 + id   command ack        device -> controller   (TPDO4)
//   0x700 + id   boot-up/heartbeat  device -> controller
//
// Encoders check ranges and return kOutOfRange / kInvalidArgument with the field named; decoders
// check ids, lengths and ranges the same way, so a controller bug becomes a clear EMCY instead of
// a silently clamped value.
#pragma once

#include <cstdint>

#include "hal/can.hpp"
#include "recog/base/status.hpp"

namespace sh::protocol {

using hal::CanFrame;

inline constexpr uint8_t kNodeIdMin = 1;
inline constexpr uint8_t kNodeIdMax = 127;

// Function codes (CiA 301 predefined connection set).
inline constexpr uint32_t kCobNmt = 0x000;
inline constexpr uint32_t kCobEmcy = 0x080;
inline constexpr uint32_t kCobResultHeader = 0x180;
inline constexpr uint32_t kCobCommand = 0x200;
inline constexpr uint32_t kCobResultObject = 0x280;
inline constexpr uint32_t kCobResultEnd = 0x380;
inline constexpr uint32_t kCobCommandAck = 0x480;
inline constexpr uint32_t kCobHeartbeat = 0x700;

Status CheckNodeId(uint8_t node_id);

// A frame with identifier `id` and `len` data bytes, all zero (the encoders fill them in).
inline CanFrame MakeFrame(uint32_t id, uint8_t len) {
  CanFrame f;
  f.id = id;
  f.len = len;
  return f;
}

// 11-bit data frame: the only kind the protocol uses (no extended ids, remote or error frames).
inline bool IsStandardDataFrame(const CanFrame& f) { return !f.extended && !f.rtr && !f.error; }

// kInvalidArgument naming `what` unless `frame` is a standard data frame on id `expected`.
Status CheckId(const CanFrame& frame, uint32_t expected, const char* what);

}  // namespace sh::protocol
