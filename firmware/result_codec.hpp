// Result sets to the PLC: the poses of one recognition as a header (0x180 + id, TPDO1), 4 object
// part frames per object (0x280 + id, TPDO2) and an end frame with the set's CRC-8 (0x380 + id,
// TPDO3); docs/can-protocol.md has the frame tables.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/cob_id.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::protocol {

// Capacity of one result set: the object index has 6 bits in the object frames.
inline constexpr size_t kMaxResultObjects = 64;
inline constexpr size_t kObjectParts = 4;  // frames per object
// Header + 4 frames per object + end frame.
inline constexpr size_t kMaxResultFrames = 2 + kObjectParts * kMaxResultObjects;
inline constexpr uint8_t kMaxModelId = 31;  // model ids are bits of the 32-bit model mask

// The object frames of a result set: part p of object i carries byte 0 = the set's sequence
// (low byte), byte 1 = p | i << 2, then the fields below. One table for the encoder
// (EncodeResultSet), the reassembler (ResultAssembler) and docs/can-protocol.md.
enum class PoseField : uint8_t { kTx, kTy, kTz, kModelId, kInstance, kScore, kQw, kQx, kQy, kQz };
struct PartField {
  PoseField field;
  uint8_t offset;  // byte in the frame
  uint8_t size;    // bytes, little-endian: 4 = int32 position, 2 = int16 quaternion / uint16
                   // score, 1 = uint8
};
struct ObjectPartLayout {
  PartField fields[3];
  uint8_t count;
};
inline constexpr ObjectPartLayout kObjectPartLayout[kObjectParts] = {
    {{{PoseField::kTx, 2, 4}, {PoseField::kModelId, 6, 1}, {PoseField::kInstance, 7, 1}}, 3},
    {{{PoseField::kTy, 2, 4}, {PoseField::kScore, 6, 2}}, 2},
    {{{PoseField::kTz, 2, 4}, {PoseField::kQw, 6, 2}}, 2},
    {{{PoseField::kQx, 2, 2}, {PoseField::kQy, 4, 2}, {PoseField::kQz, 6, 2}}, 3},
};

// Scaling of the result fields. Position: int32 in 0.01 mm (+-21.4 km, far beyond need; a
// decimal step keeps PLC arithmetic exact). Quaternion: int16 Q14 (QUnit in fixed_point.hpp).
// Score: uint16 in 0.0001.
inline constexpr double kPositionMmPerLsb = 0.01;
inline constexpr double kQuaternionPerLsb = 1.0 / 16384.0;
inline constexpr double kScorePerLsb = 0.0001;
inline constexpr double kProcessingMsPerLsb = 0.1;

enum class ResultStatus : uint8_t {
  kOk = 0,             // all selected models searched
  kTimeBudgetHit = 1,  // search stopped at the time budget; objects so far are valid
  kImageError = 2,     // no usable image pair (camera timeout, exposure); no objects
  kInternalError = 3,  // recognition failed; see the EMCY that accompanies it
  // One camera failed: the objects come from the other camera alone (monocular recognition,
  // poses still in the left camera frame). Says nothing about the time budget.
  kMonocular = 4,
};
inline constexpr uint8_t kMaxResultStatus = static_cast<uint8_t>(ResultStatus::kMonocular);

struct ObjectPose {
  uint8_t model_id = 0;                  // 0..kMaxModelId
  uint8_t instance = 0;                  // nth instance of this model in the set
  double score = 0;                      // verification score, 0..1
  double cam_t_model_mm[3] = {0, 0, 0};  // model origin in the camera frame, mm
  double cam_q_model[4] = {1, 0, 0, 0};  // rotation model -> camera, unit quaternion w,x,y,z
};

// Pose record from the recognition output: rotation matrix -> unit quaternion,
// translation copied in millimetres. Range checks happen in EncodeResultSet.
ObjectPose MakeObjectPose(const RigidTransform& cam_T_model, uint8_t model_id, uint8_t instance,
                          double score);
// The pose of a record as a transform (the inverse of MakeObjectPose's conversion, in float).
RigidTransform PoseTransform(const ObjectPose& pose);

// The table plane recognition used for a set (not sent on the bus: the simulator's RESULT lines
// and the logs name it). Names as the recogniser's JSON `table.source`.
enum class TablePlane : uint8_t { kNone = 0, kFile, kEstimated, kCarried };
const char* TablePlaneName(TablePlane p);

// The time per stage of the frame a set came from, milliseconds (host side only, like `table`:
// the commissioning page shows them). Zero for recognition without these stages (the
// simulator's ground truth) and for sets without a frame.
struct StageTimes {
  float features_ms = 0, stereo_ms = 0, hashing_ms = 0, verify_ms = 0, refine_ms = 0;
  float total_ms = 0;
};

struct ResultSet {
  uint16_t sequence = 0;    // increments per set, wraps
  uint16_t request_id = 0;  // from the trigger command; 0 = hardware trigger or free-run
  ResultStatus status = ResultStatus::kOk;
  uint32_t processing_time_us = 0;  // trigger to result; sent in 0.1 ms, saturating at 6553.5 ms
  uint8_t object_count = 0;
  // Frame of the poses (end frame byte 4): 0 left camera, 1 table, 2 robot base, 3 robot flange.
  // The field names of ObjectPose say camera; the pose is in this frame.
  uint8_t output_frame = 0;
  TablePlane table = TablePlane::kNone;  // host side only
  // Host side only: the plane of `table` in the left camera (table frame, z up from the
  // plane), whatever the output frame; valid when `table` is not kNone.
  RigidTransform left_T_table;
  StageTimes stages;  // host side only
  ObjectPose objects[kMaxResultObjects];
};

// The stream's raw fields of one pose, as the object frames carry them (also the values of the
// PDO answers and the dictionary's result records).
struct EncodedPose {
  int32_t t_raw[3];    // 0.01 mm
  int16_t q_raw[4];    // Q2.14, w >= 0
  uint16_t score_raw;  // 0.0001
};
// Range checks and rounding of one pose (`index` names the object in messages).
Status EncodePose(const ObjectPose& pose, size_t index, EncodedPose* out);

inline constexpr uint8_t kResultEndLength = 5;
inline constexpr uint8_t kMaxOutputFrame = 3;  // sequence u16, count u8, CRC-8, output frame

// Appends the frames of one set to `frames` (header, 4 per object, end frame) in transmission
// order. Errors: kOutOfRange (count, model id, score, position), kInvalidArgument (non-unit or
// non-finite quaternion, NaN), kResourceExhausted (frames too small). On error nothing is
// appended. Quaternions are normalised and sent with w >= 0 (q and -q are the same rotation).
Status EncodeResultSet(const ResultSet& set, uint8_t node_id, Vector<CanFrame>& frames);

// CRC-8 of the result set: polynomial 0x07, init 0x00, no reflection, no final xor
// (CRC-8/SMBUS; check value 0xF4 for "123456789") over the data bytes of the header frame and
// every object frame in transmission order.
uint8_t Crc8(const uint8_t* data, size_t length, uint8_t crc = 0);

}  // namespace sh::protocol
