// The process data of the dictionary: the last result set (0x2100 and one record per object at
// 0x2200 + i, readable by SDO), the answers of the PDO mode (0x2011, sent in TPDO5..8) and the
// last command acknowledge (0x2021, TPDO4). Values are the stream's raw fields (EncodePose), so a
// pose read by SDO, received in a PDO answer or in the stream is the same number.
#pragma once

#include <cstdint>

#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"

namespace sh::canopen {

// 0x2011 sub 3.
enum class AnswerStatus : uint8_t {
  kOk = 0,
  kNoObject = 1,  // object index >= the set's object count: pose fields 0
  kNoSet = 2,     // no result set since boot
};

class ResultObjects {
 public:
  explicit ResultObjects(ObjectDictionary* od) : od_(od) {}

  // Stores a set (its poses are range-checked by EncodePose; on error nothing is stored) with
  // the CRC-8 of its stream frames.
  Status Store(const protocol::ResultSet& set, uint8_t crc);
  // Fills 0x2011 with the answer to request (counter, object index) from the stored set.
  AnswerStatus Answer(uint8_t counter, uint8_t index);
  bool have_set() const { return have_set_; }

 private:
  ObjectDictionary* od_;
  bool have_set_ = false;
};

// 0x2021 from an acknowledge (then PackTpdo(kTpdoAck) gives the ack frame).
void StoreCommandAck(ObjectDictionary* od, const protocol::CommandAck& ack);

}  // namespace sh::canopen
