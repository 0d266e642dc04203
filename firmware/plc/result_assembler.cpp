#include "firmware/plc/result_assembler.hpp"

#include <cstdint>

#include "firmware/le_bytes.hpp"
#include "recog/base/fixed_point.hpp"

namespace sh::protocol {
namespace {

// Sets one field of a pose from its wire value (positions and quaternion components signed: the
// casts reinterpret the unsigned word in two's complement, modulo 2^N).
void SetFromWire(PoseField field, uint32_t raw, ObjectPose* pose) {
  switch (field) {
    case PoseField::kTx:
    case PoseField::kTy:
    case PoseField::kTz:
      // int32 in 0.01 mm.
      pose->cam_t_model_mm[static_cast<int>(field) - static_cast<int>(PoseField::kTx)] =
          static_cast<int32_t>(raw) * kPositionMmPerLsb;
      break;
    case PoseField::kModelId:
      pose->model_id = static_cast<uint8_t>(raw);
      break;
    case PoseField::kInstance:
      pose->instance = static_cast<uint8_t>(raw);
      break;
    case PoseField::kScore:
      pose->score = static_cast<uint16_t>(raw) * kScorePerLsb;  // uint16 in 0.0001
      break;
    case PoseField::kQw:
    case PoseField::kQx:
    case PoseField::kQy:
    case PoseField::kQz:
      // int16 Q2.14.
      pose->cam_q_model[static_cast<int>(field) - static_cast<int>(PoseField::kQw)] =
          QUnit::FromRaw(static_cast<int16_t>(raw)).ToDouble();
      break;
  }
}

uint32_t GetLe(const uint8_t* p, uint8_t size) {
  uint32_t v = 0;
  for (uint8_t b = 0; b < size; ++b) v |= uint32_t{p[b]} << (8 * b);
  return v;
}

}  // namespace

Result<bool> ResultAssembler::Feed(const CanFrame& frame) {
  if (!IsStandardDataFrame(frame)) return false;
  if (frame.id == kCobResultHeader + node_id_) {
    const bool was_in_set = in_set_;
    const uint16_t previous = set_.sequence;
    in_set_ = false;
    if (frame.len != 8) {
      return Status::Error(StatusCode::kInvalidArgument, "result header has %u bytes, expected 8",
                           frame.len);
    }
    if (frame.data[2] > kMaxResultObjects || frame.data[3] > kMaxResultStatus) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "result header: %u objects / status %u out of range", frame.data[2],
                           frame.data[3]);
    }
    set_ = ResultSet();
    set_.sequence = GetU16(&frame.data[0]);
    set_.object_count = frame.data[2];
    set_.status = static_cast<ResultStatus>(frame.data[3]);
    set_.processing_time_us = static_cast<uint32_t>(GetU16(&frame.data[4])) * 100u;
    set_.request_id = GetU16(&frame.data[6]);
    crc_ = Crc8(frame.data, frame.len);
    next_object_frame_ = 0;
    in_set_ = true;
    if (was_in_set) {
      return Status::Error(StatusCode::kDataLoss,
                           "result set %u incomplete: header of set %u arrived first", previous,
                           set_.sequence);
    }
    return false;
  }
  if (frame.id == kCobResultObject + node_id_) {
    if (!in_set_) {
      return Status::Error(StatusCode::kDataLoss, "result object frame without a header");
    }
    const size_t index = frame.data[1] >> 2;
    const size_t part = frame.data[1] & 3;
    if (frame.len != 8 || frame.data[0] != static_cast<uint8_t>(set_.sequence) ||
        index * kObjectParts + part != next_object_frame_ || index >= set_.object_count) {
      in_set_ = false;
      return Status::Error(StatusCode::kDataLoss,
                           "result set %u: expected object %zu part %zu, got seq %u object %zu "
                           "part %zu",
                           set_.sequence, next_object_frame_ / kObjectParts,
                           next_object_frame_ % kObjectParts, frame.data[0], index, part);
    }
    ObjectPose& pose = set_.objects[index];
    const uint8_t* d = frame.data;
    const ObjectPartLayout& layout = kObjectPartLayout[part];
    for (uint8_t k = 0; k < layout.count; ++k) {
      const PartField& field = layout.fields[k];
      SetFromWire(field.field, GetLe(&d[field.offset], field.size), &pose);
    }
    crc_ = Crc8(frame.data, frame.len, crc_);
    ++next_object_frame_;
    return false;
  }
  if (frame.id == kCobResultEnd + node_id_) {
    if (!in_set_) return Status::Error(StatusCode::kDataLoss, "result end frame without a header");
    in_set_ = false;
    // 4 bytes from firmware that predates the output frame byte (camera frame).
    if (frame.len != kResultEndLength && frame.len != 4) {
      return Status::Error(StatusCode::kInvalidArgument, "result end has %u bytes, expected %u",
                           frame.len, kResultEndLength);
    }
    set_.output_frame = frame.len > 4 ? frame.data[4] : 0;
    if (GetU16(&frame.data[0]) != set_.sequence || frame.data[2] != set_.object_count ||
        next_object_frame_ != kObjectParts * set_.object_count) {
      return Status::Error(StatusCode::kDataLoss,
                           "result set %u: end frame (seq %u, %u objects) after %zu of %zu "
                           "object frames",
                           set_.sequence, GetU16(&frame.data[0]), frame.data[2], next_object_frame_,
                           kObjectParts * set_.object_count);
    }
    if (frame.data[3] != crc_) {
      return Status::Error(StatusCode::kDataLoss,
                           "result set %u: CRC-8 0x%02X received, 0x%02X computed", set_.sequence,
                           frame.data[3], crc_);
    }
    return true;
  }
  return false;
}

}  // namespace sh::protocol
