#include "firmware/can_protocol.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "firmware/le_bytes.hpp"
#include "recog/base/fixed_point.hpp"

namespace sh::protocol {
namespace {

CanFrame MakeFrame(uint32_t id, uint8_t len) {
  CanFrame f;
  f.id = id;
  f.len = len;
  return f;
}

bool IsStandardDataFrame(const CanFrame& f) { return !f.extended && !f.rtr && !f.error; }

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

// Length of the command frame that holds all arguments of `code`; 0 for an unknown code.
uint8_t CommandLength(uint8_t code) {
  switch (static_cast<CommandCode>(code)) {
    case CommandCode::kTrigger:
      return 3;
    case CommandCode::kSelectModels:
      return 5;
    case CommandCode::kSetTimeBudget:
      return 3;
    case CommandCode::kClearFault:
      return 1;
    case CommandCode::kSetFreeRunRate:
      return 3;
  }
  return 0;
}

Status CheckCommandArguments(const Command& c) {
  switch (c.code) {
    case CommandCode::kTrigger:
      if (c.request_id == 0) {
        return Status::Error(StatusCode::kOutOfRange,
                             "trigger: request id 0 is reserved for hardware/free-run results; "
                             "use 1..65535");
      }
      return Status::Ok();
    case CommandCode::kSelectModels:
      if (c.model_mask == 0) {
        return Status::Error(StatusCode::kOutOfRange,
                             "select models: mask 0x00000000 selects no model");
      }
      return Status::Ok();
    case CommandCode::kSetTimeBudget:
      if (c.time_budget_ms < kTimeBudgetMinMs || c.time_budget_ms > kTimeBudgetMaxMs) {
        return Status::Error(StatusCode::kOutOfRange, "set time budget: %u ms is outside %u..%u ms",
                             c.time_budget_ms, kTimeBudgetMinMs, kTimeBudgetMaxMs);
      }
      return Status::Ok();
    case CommandCode::kClearFault:
      return Status::Ok();
    case CommandCode::kSetFreeRunRate:
      if (c.free_run_rate_dhz > kFreeRunRateMaxDeciHz) {
        return Status::Error(StatusCode::kOutOfRange,
                             "set free-run rate: %u.%u Hz is above %u.%u Hz (0 = off)",
                             c.free_run_rate_dhz / 10, c.free_run_rate_dhz % 10,
                             kFreeRunRateMaxDeciHz / 10, kFreeRunRateMaxDeciHz % 10);
      }
      return Status::Ok();
  }
  return Status::Error(StatusCode::kInvalidArgument, "unknown command code 0x%02X",
                       static_cast<unsigned>(c.code));
}

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

Status CheckNodeId(uint8_t node_id) {
  if (node_id < kNodeIdMin || node_id > kNodeIdMax) {
    return Status::Error(StatusCode::kOutOfRange, "CAN node id %u is outside %u..%u", node_id,
                         kNodeIdMin, kNodeIdMax);
  }
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

const char* CommandName(CommandCode code) {
  switch (code) {
    case CommandCode::kTrigger:
      return "trigger";
    case CommandCode::kSelectModels:
      return "select models";
    case CommandCode::kSetTimeBudget:
      return "set time budget";
    case CommandCode::kClearFault:
      return "clear fault";
    case CommandCode::kSetFreeRunRate:
      return "set free-run rate";
  }
  return "unknown";
}

// ----------------------------------------------------------------------------- NMT, heartbeat

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

// ----------------------------------------------------------------------------- commands

Result<CanFrame> EncodeCommand(const Command& command, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckCommandArguments(command));
  CanFrame f = MakeFrame(kCobCommand + node_id, 8);
  f.data[0] = static_cast<uint8_t>(command.code);
  switch (command.code) {
    case CommandCode::kTrigger:
      PutU16(&f.data[1], command.request_id);
      break;
    case CommandCode::kSelectModels:
      PutU32(&f.data[1], command.model_mask);
      break;
    case CommandCode::kSetTimeBudget:
      PutU16(&f.data[1], command.time_budget_ms);
      break;
    case CommandCode::kClearFault:
      break;
    case CommandCode::kSetFreeRunRate:
      PutU16(&f.data[1], command.free_run_rate_dhz);
      break;
  }
  return f;
}

Result<Command> DecodeCommand(const CanFrame& frame, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckId(frame, kCobCommand + node_id, "command"));
  if (frame.len == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "command frame is empty");
  }
  const uint8_t code = frame.data[0];
  const uint8_t needed = CommandLength(code);
  if (needed == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "unknown command code 0x%02X", code);
  }
  Command c;
  c.code = static_cast<CommandCode>(code);
  if (frame.len < needed) {
    return Status::Error(StatusCode::kInvalidArgument, "%s command has %u bytes, needs at least %u",
                         CommandName(c.code), frame.len, needed);
  }
  switch (c.code) {
    case CommandCode::kTrigger:
      c.request_id = GetU16(&frame.data[1]);
      break;
    case CommandCode::kSelectModels:
      c.model_mask = GetU32(&frame.data[1]);
      break;
    case CommandCode::kSetTimeBudget:
      c.time_budget_ms = GetU16(&frame.data[1]);
      break;
    case CommandCode::kClearFault:
      break;
    case CommandCode::kSetFreeRunRate:
      c.free_run_rate_dhz = GetU16(&frame.data[1]);
      break;
  }
  SH_RETURN_IF_ERROR(CheckCommandArguments(c));
  return c;
}

Status CheckModelMask(uint32_t model_mask, size_t loaded_model_count) {
  if (model_mask == 0) {
    return Status::Error(StatusCode::kOutOfRange, "model mask selects no model");
  }
  const uint32_t allowed =
      loaded_model_count >= 32 ? 0xFFFFFFFFu : (uint32_t{1} << loaded_model_count) - 1u;
  if (model_mask & ~allowed) {
    return Status::Error(StatusCode::kOutOfRange,
                         "model mask 0x%08X names models beyond the %zu loaded (valid 0x%08X)",
                         model_mask, loaded_model_count, allowed);
  }
  return Status::Ok();
}

Result<CanFrame> EncodeCommandAck(const CommandAck& ack, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  CanFrame f = MakeFrame(kCobCommandAck + node_id, 8);
  f.data[0] = ack.command_code;
  f.data[1] = ack.status;
  PutU16(&f.data[2], ack.request_id);
  PutU32(&f.data[4], ack.value);
  return f;
}

Result<CommandAck> DecodeCommandAck(const CanFrame& frame, uint8_t node_id) {
  SH_RETURN_IF_ERROR(CheckNodeId(node_id));
  SH_RETURN_IF_ERROR(CheckId(frame, kCobCommandAck + node_id, "command ack"));
  if (frame.len != 8) {
    return Status::Error(StatusCode::kInvalidArgument, "command ack has %u bytes, expected 8",
                         frame.len);
  }
  CommandAck a;
  a.command_code = frame.data[0];
  a.status = frame.data[1];
  a.request_id = GetU16(&frame.data[2]);
  a.value = GetU32(&frame.data[4]);
  return a;
}

CommandAck MakeCommandAck(const CanFrame& command_frame, const Status& status) {
  CommandAck a;
  a.command_code = command_frame.len > 0 ? command_frame.data[0] : 0;
  a.status = static_cast<uint8_t>(status.code());
  uint8_t args[7] = {};
  for (uint8_t i = 1; i < command_frame.len && i < 8; ++i) args[i - 1] = command_frame.data[i];
  switch (static_cast<CommandCode>(a.command_code)) {
    case CommandCode::kTrigger:
      a.request_id = GetU16(args);
      break;
    case CommandCode::kSelectModels:
      a.value = GetU32(args);
      break;
    case CommandCode::kSetTimeBudget:
    case CommandCode::kSetFreeRunRate:
      a.value = GetU16(args);
      break;
    case CommandCode::kClearFault:
      break;
  }
  return a;
}

// ----------------------------------------------------------------------------- results

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

// Little-endian `size` bytes of v at data[offset]. The part layouts keep every field inside the
// 8 data bytes; the bound is written out so that the compiler sees it too (GCC otherwise warns of
// writes past the frame when it unrolls the loop for an unknown size).
void PutLe(uint8_t (&data)[hal::kCanMaxDataBytes], uint8_t offset, uint8_t size, uint32_t v) {
  for (uint8_t b = 0; b < size && offset + b < hal::kCanMaxDataBytes; ++b) {
    data[offset + b] = static_cast<uint8_t>(v >> (8 * b));
  }
}

uint32_t GetLe(const uint8_t* p, uint8_t size) {
  uint32_t v = 0;
  for (uint8_t b = 0; b < size; ++b) v |= uint32_t{p[b]} << (8 * b);
  return v;
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

// ----------------------------------------------------------------------------- EMCY

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

Emcy MakeCommandRejectedEmcy(const CanFrame& command_frame, const Status& status,
                             FirmwareState state) {
  const uint8_t code = command_frame.len > 0 ? command_frame.data[0] : 0;
  const uint8_t needed = CommandLength(code);
  const bool short_frame = command_frame.len == 0 || (needed != 0 && command_frame.len < needed);
  Emcy e;
  e.error_code =
      static_cast<uint16_t>(short_frame ? EmcyCode::kPdoLengthError : EmcyCode::kProtocolError);
  e.error_register = ErrorRegisterFor(e.error_code);
  e.state = state;
  const uint16_t value =
      static_cast<uint16_t>((command_frame.len > 1 ? command_frame.data[1] : 0) |
                            (command_frame.len > 2 ? command_frame.data[2] << 8 : 0));
  e.detail = static_cast<uint32_t>(code) << 24 |
             static_cast<uint32_t>(static_cast<uint8_t>(status.code())) << 16 | value;
  return e;
}

}  // namespace sh::protocol
