// The controller side of the result stream: reassembles and checks the result sets the device
// sends (result_codec.hpp). The simulator's demo PLC and the tests use it; it is the reference
// for PLC implementations and no part of the board program.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/result_codec.hpp"
#include "recog/base/status.hpp"

namespace sh::protocol {

class ResultAssembler {
 public:
  explicit ResultAssembler(uint8_t node_id) : node_id_(node_id) {}
  // true: a complete set passed all checks and is in set(). false: frame consumed, set still
  // incomplete (or the frame was not a result frame). kDataLoss: a set was broken (missing or
  // out-of-order frame, CRC mismatch, count mismatch); the assembler then waits for the next
  // header. kInvalidArgument: a frame's content is invalid.
  Result<bool> Feed(const CanFrame& frame);
  const ResultSet& set() const { return set_; }

 private:
  uint8_t node_id_;
  bool in_set_ = false;
  size_t next_object_frame_ = 0;
  uint8_t crc_ = 0;
  ResultSet set_;
};

}  // namespace sh::protocol
