#include "firmware/canopen/result_objects.hpp"

#include "firmware/canopen/od_table.hpp"

namespace sh::canopen {

Status ResultObjects::Store(const protocol::ResultSet& set, uint8_t crc) {
  if (set.object_count > protocol::kMaxResultObjects) {
    return Status::Error(StatusCode::kOutOfRange, "result set has %u objects, at most %zu",
                         set.object_count, protocol::kMaxResultObjects);
  }
  protocol::EncodedPose encoded[protocol::kMaxResultObjects];
  for (size_t i = 0; i < set.object_count; ++i) {
    SH_RETURN_IF_ERROR(protocol::EncodePose(set.objects[i], i, &encoded[i]));
  }
  // us -> 0.1 ms as in the header frame: rounded, saturating.
  const uint32_t time_raw = (set.processing_time_us + 50) / 100;
  od_->Set(kIdxResultSet, kSubSetSequence, set.sequence);
  od_->Set(kIdxResultSet, kSubSetCount, set.object_count);
  od_->Set(kIdxResultSet, kSubSetStatus, static_cast<uint8_t>(set.status));
  od_->Set(kIdxResultSet, kSubSetTime, time_raw > 0xFFFF ? 0xFFFF : time_raw);
  od_->Set(kIdxResultSet, kSubSetRequestId, set.request_id);
  od_->Set(kIdxResultSet, kSubSetFrame, set.output_frame);
  od_->Set(kIdxResultSet, kSubSetCrc, crc);
  for (size_t i = 0; i < protocol::kMaxResultObjects; ++i) {
    const uint16_t index = static_cast<uint16_t>(kIdxResultObject + i);
    const bool present = i < set.object_count;
    const protocol::EncodedPose e = present ? encoded[i] : protocol::EncodedPose{};
    od_->Set(index, kSubObjModel, present ? set.objects[i].model_id : 0);
    od_->Set(index, kSubObjInstance, present ? set.objects[i].instance : 0);
    od_->Set(index, kSubObjScore, e.score_raw);
    od_->Set(index, kSubObjX, e.t_raw[0]);
    od_->Set(index, kSubObjY, e.t_raw[1]);
    od_->Set(index, kSubObjZ, e.t_raw[2]);
    od_->Set(index, kSubObjQw, e.q_raw[0]);
    od_->Set(index, kSubObjQx, e.q_raw[1]);
    od_->Set(index, kSubObjQy, e.q_raw[2]);
    od_->Set(index, kSubObjQz, e.q_raw[3]);
  }
  have_set_ = true;
  return Status::Ok();
}

AnswerStatus ResultObjects::Answer(uint8_t counter, uint8_t index) {
  const uint8_t count = static_cast<uint8_t>(od_->Get(kIdxResultSet, kSubSetCount));
  AnswerStatus status = AnswerStatus::kOk;
  if (!have_set_) {
    status = AnswerStatus::kNoSet;
  } else if (index >= count) {
    status = AnswerStatus::kNoObject;
  }
  const bool ok = status == AnswerStatus::kOk;
  const uint16_t obj = static_cast<uint16_t>(kIdxResultObject + (ok ? index : 0));
  const auto copy = [&](uint8_t answer_sub, uint8_t object_sub) {
    od_->Set(kIdxObjectAnswer, answer_sub, ok ? od_->Get(obj, object_sub) : 0);
  };
  od_->Set(kIdxObjectAnswer, kSubAnswerCounter, counter);
  od_->Set(kIdxObjectAnswer, kSubAnswerIndex, index);
  od_->Set(kIdxObjectAnswer, kSubAnswerStatus, static_cast<uint8_t>(status));
  copy(kSubAnswerModel, kSubObjModel);
  copy(kSubAnswerInstance, kSubObjInstance);
  copy(kSubAnswerScore, kSubObjScore);
  copy(kSubAnswerX, kSubObjX);
  copy(kSubAnswerY, kSubObjY);
  copy(kSubAnswerZ, kSubObjZ);
  copy(kSubAnswerQw, kSubObjQw);
  copy(kSubAnswerQx, kSubObjQx);
  copy(kSubAnswerQy, kSubObjQy);
  copy(kSubAnswerQz, kSubObjQz);
  // The set the answer belongs to: a PLC compares it with the header it saw.
  od_->Set(kIdxObjectAnswer, kSubAnswerSequence,
           have_set_ ? od_->Get(kIdxResultSet, kSubSetSequence) & 0xFF : 0);
  od_->Set(kIdxObjectAnswer, kSubAnswerCount, have_set_ ? count : 0);
  od_->Set(kIdxObjectAnswer, kSubAnswerFrame, od_->Get(kIdxResultSet, kSubSetFrame));
  return status;
}

void StoreCommandAck(ObjectDictionary* od, const protocol::CommandAck& ack) {
  od->Set(kIdxCommandAck, 1, ack.command_code);
  od->Set(kIdxCommandAck, 2, ack.status);
  od->Set(kIdxCommandAck, 3, ack.request_id);
  od->Set(kIdxCommandAck, 4, ack.value);
}

}  // namespace sh::canopen
