#include "firmware/canopen/nmt.hpp"

#include <cstdint>

namespace sh::protocol {

const char* NmtStateName(NmtState state) {
  switch (state) {
    case NmtState::kBootUp:
      return "boot-up";
    case NmtState::kStopped:
      return "stopped";
    case NmtState::kOperational:
      return "operational";
    case NmtState::kPreOperational:
      return "pre-operational";
  }
  return "unknown";
}

Result<CanFrame> EncodeBootUp(uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  CanFrame f = MakeFrame(kCobHeartbeat + node_id, 1);
  f.data[0] = static_cast<uint8_t>(NmtState::kBootUp);
  return f;
}

Result<CanFrame> EncodeHeartbeat(uint8_t node_id, NmtState state) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  if (state != NmtState::kStopped && state != NmtState::kOperational &&
      state != NmtState::kPreOperational) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "heartbeat state 0x%02X is not stopped/operational/pre-operational",
                         static_cast<unsigned>(state));
  }
  CanFrame f = MakeFrame(kCobHeartbeat + node_id, 1);
  f.data[0] = static_cast<uint8_t>(state);
  return f;
}

Result<NmtState> DecodeHeartbeat(const CanFrame& frame, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckId(frame, kCobHeartbeat + node_id, "heartbeat"));
  if (frame.len != 1) {
    return Status::Error(StatusCode::kInvalidArgument, "heartbeat has %u bytes, expected 1",
                         frame.len);
  }
  const uint8_t s = frame.data[0] & 0x7F;  // bit 7 is the CANopen node-guarding toggle
  switch (static_cast<NmtState>(s)) {
    case NmtState::kBootUp:
    case NmtState::kStopped:
    case NmtState::kOperational:
    case NmtState::kPreOperational:
      return static_cast<NmtState>(s);
  }
  return Status::Error(StatusCode::kInvalidArgument, "heartbeat state 0x%02X unknown", s);
}

Result<NmtRequest> DecodeNmt(const CanFrame& frame, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckId(frame, kCobNmt, "NMT"));
  if (frame.len != 2) {
    return Status::Error(StatusCode::kInvalidArgument, "NMT frame has %u bytes, expected 2",
                         frame.len);
  }
  NmtRequest r;
  switch (static_cast<NmtCommand>(frame.data[0])) {
    case NmtCommand::kStart:
    case NmtCommand::kStop:
    case NmtCommand::kEnterPreOperational:
    case NmtCommand::kResetNode:
    case NmtCommand::kResetCommunication:
      r.command = static_cast<NmtCommand>(frame.data[0]);
      break;
    default:
      return Status::Error(StatusCode::kInvalidArgument, "NMT command 0x%02X unknown",
                           frame.data[0]);
  }
  if (frame.data[1] > kNodeIdMax) {
    return Status::Error(StatusCode::kOutOfRange, "NMT target node %u > %u", frame.data[1],
                         kNodeIdMax);
  }
  r.target_node = frame.data[1];
  r.addressed = r.target_node == 0 || r.target_node == node_id;
  return r;
}

Result<CanFrame> EncodeNmt(NmtCommand command, uint8_t target_node) {
  if (target_node > kNodeIdMax) {
    return Status::Error(StatusCode::kOutOfRange, "NMT target node %u > %u", target_node,
                         kNodeIdMax);
  }
  CanFrame f = MakeFrame(kCobNmt, 2);
  f.data[0] = static_cast<uint8_t>(command);
  f.data[1] = target_node;
  return f;
}

}  // namespace sh::protocol
