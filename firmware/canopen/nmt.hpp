// NMT (0x000), boot-up and heartbeat (0x700 + id) frames of the device (CiA 301).
#pragma once

#include <cstdint>

#include "firmware/canopen/cob_id.hpp"
#include "recog/base/status.hpp"

namespace sh::protocol {

enum class NmtState : uint8_t {
  kBootUp = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};
const char* NmtStateName(NmtState state);

enum class NmtCommand : uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

// Boot-up message: 0x700 + id, one byte 0x00. Sent once after start-up.
Result<CanFrame> EncodeBootUp(uint8_t node_id);
// Heartbeat: 0x700 + id, one byte NMT state (not kBootUp).
Result<CanFrame> EncodeHeartbeat(uint8_t node_id, NmtState state);
Result<NmtState> DecodeHeartbeat(const CanFrame& frame, uint8_t node_id);

// NMT frame 0x000, 2 bytes: [command, target node (0 = all nodes)]. A valid command for another
// node decodes with addressed = false.
struct NmtRequest {
  NmtCommand command = NmtCommand::kStart;
  uint8_t target_node = 0;
  bool addressed = false;  // target_node is 0 or this node
};
Result<NmtRequest> DecodeNmt(const CanFrame& frame, uint8_t node_id);
Result<CanFrame> EncodeNmt(NmtCommand command, uint8_t target_node);

}  // namespace sh::protocol
