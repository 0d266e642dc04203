#include "firmware/result_codec.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "firmware/le_bytes.hpp"
#include "recog/base/fixed_point.hpp"

namespace sh::protocol {
namespace {

// Position mm -> int32 in 0.01 mm, rounded to nearest. Out of int32 range is an error rather
// than a saturated value: a clamped coordinate would send the robot to a wrong place.
Status PositionToRaw(double mm, const char* axis, int32_t* raw) {
  if (!std::isfinite(mm)) {
    return Status::Error(StatusCode::kInvalidArgument, "position %s is not finite", axis);
  }
  const double scaled = std::nearbyint(mm / kPositionMmPerLsb);
  if (scaled > std::numeric_limits<int32_t>::max() ||
      scaled < std::numeric_limits<int32_t>::min()) {
    return Status::Error(StatusCode::kOutOfRange,
                         "position %s = %.2f mm exceeds the int32 0.01 mm range", axis, mm);
  }
  *raw = static_cast<int32_t>(scaled);
  return Status::Ok();
}

}  // namespace

Status EncodePose(const ObjectPose& pose, size_t index, EncodedPose* out) {
  if (pose.model_id > kMaxModelId) {
    return Status::Error(StatusCode::kOutOfRange, "object %zu: model id %u > %u", index,
                         pose.model_id, kMaxModelId);
  }
  if (!(pose.score >= 0.0 && pose.score <= 1.0)) {
    return Status::Error(StatusCode::kOutOfRange, "object %zu: score %g is outside 0..1", index,
                         pose.score);
  }
  static const char* const kAxes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const Status s = PositionToRaw(pose.cam_t_model_mm[a], kAxes[a], &out->t_raw[a]);
    if (!s.ok()) return s.WithContext("object %zu", index);
  }
  const double* q = pose.cam_q_model;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  // 1e-3 accepts quaternions derived from float rotation matrices and rejects garbage.
  if (!std::isfinite(norm) || std::fabs(norm - 1.0) > 1e-3) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "object %zu: quaternion norm %g is not 1 (w x y z = %g %g %g %g)", index,
                         norm, q[0], q[1], q[2], q[3]);
  }
  // Canonical sign w >= 0 so that equal rotations give equal frames.
  const double sign = q[0] < 0 ? -1.0 : 1.0;
  for (int i = 0; i < 4; ++i) {
    // unit component -> Q2.14 (QUnit), round to nearest; |c| <= 1 never saturates.
    out->q_raw[i] = QUnit::FromDouble(sign * q[i] / norm).raw();
  }
  // score 0..1 -> 0.0001 steps, round to nearest (max 10000 fits uint16).
  out->score_raw = static_cast<uint16_t>(std::lround(pose.score / kScorePerLsb));
  return Status::Ok();
}

const char* TablePlaneName(TablePlane p) {
  switch (p) {
    case TablePlane::kNone:
      return "none";
    case TablePlane::kFile:
      return "file";
    case TablePlane::kEstimated:
      return "estimated";
    case TablePlane::kCarried:
      return "carried";
  }
  return "unknown";
}

ObjectPose MakeObjectPose(const RigidTransform& cam_T_model, uint8_t model_id, uint8_t instance,
                          double score) {
  ObjectPose pose;
  pose.model_id = model_id;
  pose.instance = instance;
  pose.score = score;
  // Double precision for the conversion: the float matrix is only approximately orthonormal and
  // Eigen's quaternion-from-matrix is well conditioned for every rotation.
  const Eigen::Quaterniond q(cam_T_model.R.cast<double>());
  // The sign the bus sends (w >= 0), so that result.json and the stdout lines say the same.
  const Eigen::Quaterniond n = q.normalized();
  const double sign = n.w() < 0 ? -1.0 : 1.0;
  pose.cam_q_model[0] = sign * n.w();
  pose.cam_q_model[1] = sign * n.x();
  pose.cam_q_model[2] = sign * n.y();
  pose.cam_q_model[3] = sign * n.z();
  for (int i = 0; i < 3; ++i) pose.cam_t_model_mm[i] = cam_T_model.t_mm[i];
  return pose;
}

RigidTransform PoseTransform(const ObjectPose& pose) {
  const Eigen::Quaternionf q(float(pose.cam_q_model[0]), float(pose.cam_q_model[1]),
                             float(pose.cam_q_model[2]), float(pose.cam_q_model[3]));
  RigidTransform t;
  t.R = q.normalized().toRotationMatrix();
  for (int i = 0; i < 3; ++i) t.t_mm[i] = float(pose.cam_t_model_mm[i]);
  return t;
}

uint8_t Crc8(const uint8_t* data, size_t length, uint8_t crc) {
  for (size_t i = 0; i < length; ++i) {
    crc ^= data[i];
    for (int b = 0; b < 8; ++b) {
      crc = static_cast<uint8_t>(crc & 0x80 ? (crc << 1) ^ 0x07 : crc << 1);
    }
  }
  return crc;
}

namespace {

// The wire value of one field of an object part (kObjectPartLayout), as an unsigned word.
uint32_t WireValue(PoseField field, const EncodedPose& e, const ObjectPose& pose) {
  switch (field) {
    case PoseField::kTx:
    case PoseField::kTy:
    case PoseField::kTz:
      return static_cast<uint32_t>(
          e.t_raw[static_cast<int>(field) - static_cast<int>(PoseField::kTx)]);
    case PoseField::kModelId:
      return pose.model_id;
    case PoseField::kInstance:
      return pose.instance;
    case PoseField::kScore:
      return e.score_raw;
    case PoseField::kQw:
    case PoseField::kQx:
    case PoseField::kQy:
    case PoseField::kQz:
      return static_cast<uint16_t>(
          e.q_raw[static_cast<int>(field) - static_cast<int>(PoseField::kQw)]);
  }
  return 0;
}

// Little-endian `size` bytes of v at data[offset]. The part layouts keep every field inside the
// 8 data bytes; the bound is written out so that the compiler sees it too (GCC otherwise warns of
// writes past the frame when it unrolls the loop for an unknown size).
void PutLe(uint8_t (&data)[hal::kCanMaxDataBytes], uint8_t offset, uint8_t size, uint32_t v) {
  for (uint8_t b = 0; b < size && offset + b < hal::kCanMaxDataBytes; ++b) {
    data[offset + b] = static_cast<uint8_t>(v >> (8 * b));
  }
}

}  // namespace

Status EncodeResultSet(const ResultSet& set, uint8_t node_id, Vector<CanFrame>& frames) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  if (set.object_count > kMaxResultObjects) {
    return Status::Error(StatusCode::kOutOfRange, "result set has %u objects, at most %zu",
                         set.object_count, kMaxResultObjects);
  }
  if (static_cast<uint8_t>(set.status) > kMaxResultStatus) {
    return Status::Error(StatusCode::kOutOfRange, "result status %u unknown",
                         static_cast<unsigned>(set.status));
  }
  if (set.output_frame > kMaxOutputFrame) {
    return Status::Error(
        StatusCode::kOutOfRange,
        "output frame %u unknown (0 camera, 1 table, 2 robot base, 3 robot flange)",
        set.output_frame);
  }
  const size_t needed = 2 + kObjectParts * set.object_count;
  if (frames.capacity() - frames.size() < needed) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "result set needs %zu frames, only %zu free", needed,
                         frames.capacity() - frames.size());
  }
  EncodedPose encoded[kMaxResultObjects];
  for (size_t i = 0; i < set.object_count; ++i) {
    SH_RETURN_IF_ERROR(EncodePose(set.objects[i], i, &encoded[i]));
  }

  // us -> 0.1 ms, rounded; saturates so that a very long run still reports "at least 6553.5 ms".
  const uint32_t time_raw = (set.processing_time_us + 50) / 100;
  CanFrame header = MakeFrame(kCobResultHeader + node_id, 8);
  PutU16(&header.data[0], set.sequence);
  header.data[2] = set.object_count;
  header.data[3] = static_cast<uint8_t>(set.status);
  PutU16(&header.data[4], static_cast<uint16_t>(time_raw > 0xFFFF ? 0xFFFF : time_raw));
  PutU16(&header.data[6], set.request_id);
  uint8_t crc = Crc8(header.data, header.len);
  (void)frames.push_back(header);  // capacity checked above

  const uint8_t seq8 = static_cast<uint8_t>(set.sequence);
  for (size_t i = 0; i < set.object_count; ++i) {
    const EncodedPose& e = encoded[i];
    for (uint8_t part = 0; part < kObjectParts; ++part) {
      CanFrame f = MakeFrame(kCobResultObject + node_id, 8);
      f.data[0] = seq8;
      f.data[1] = static_cast<uint8_t>(part | i << 2);
      const ObjectPartLayout& layout = kObjectPartLayout[part];
      for (uint8_t k = 0; k < layout.count; ++k) {
        const PartField& field = layout.fields[k];
        PutLe(f.data, field.offset, field.size, WireValue(field.field, e, set.objects[i]));
      }
      crc = Crc8(f.data, f.len, crc);
      (void)frames.push_back(f);
    }
  }
  CanFrame end = MakeFrame(kCobResultEnd + node_id, kResultEndLength);
  PutU16(&end.data[0], set.sequence);
  end.data[2] = set.object_count;
  end.data[3] = crc;
  end.data[4] = set.output_frame;
  (void)frames.push_back(end);
  return Status::Ok();
}

}  // namespace sh::protocol
