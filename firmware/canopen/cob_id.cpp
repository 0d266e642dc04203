#include "firmware/canopen/cob_id.hpp"

namespace sh::protocol {

Status CheckNodeId(uint8_t node_id) {
  if (node_id < kNodeIdMin || node_id > kNodeIdMax) {
    return Status::Error(StatusCode::kOutOfRange, "CAN node id %u is outside %u..%u", node_id,
                         kNodeIdMin, kNodeIdMax);
  }
  return Status::Ok();
}

Status CheckId(const CanFrame& frame, uint32_t expected, const char* what) {
  if (!IsStandardDataFrame(frame) || frame.id != expected) {
    return Status::Error(StatusCode::kInvalidArgument, "%s frame expected on id 0x%03X, got 0x%X%s",
                         what, expected, frame.id,
                         frame.extended ? " (extended)"
                         : frame.rtr    ? " (remote)"
                                        : "");
  }
  return Status::Ok();
}

}  // namespace sh::protocol
