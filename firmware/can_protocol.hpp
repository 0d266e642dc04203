// CAN protocol between the vision board and the PLC (docs/can-protocol.md has the frame tables;
// firmware/stereohash.dbc describes the same frames for CAN tools).
//
// CANopen-compatible identifiers from the predefined connection set: COB-ID = function code +
// node id (1..127). All multi-byte fields are little-endian (CANopen byte order).
//
//   0x000        NMT command        controller -> device   (start/stop/pre-op/reset)
//   0x080 + id   EMCY               device -> controller   (error code, register, state, detail)
//   0x180 + id   result header      device -> controller   (TPDO1)
//   0x200 + id   command            controller -> device   (RPDO1)
//   0x280 + id   result object part device -> controller   (TPDO2, multiplexed: 4 parts/object)
//   0x380 + id   result end         device -> controller   (TPDO3, count + CRC-8 of the set)
//   0x480 + id   command ack        device -> controller   (TPDO4)
//   0x700 + id   boot-up/heartbeat  device -> controller
//
// Encoders check ranges and return kOutOfRange / kInvalidArgument with the field named; decoders
// check ids, lengths and ranges the same way, so a controller bug becomes a clear EMCY instead of
// a silently clamped value.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/can.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::protocol {

using hal::CanFrame;

inline constexpr uint8_t kNodeIdMin = 1;
inline constexpr uint8_t kNodeIdMax = 127;

// Function codes (CiA 301 predefined connection set).
inline constexpr uint32_t kCobNmt = 0x000;
inline constexpr uint32_t kCobEmcy = 0x080;
inline constexpr uint32_t kCobResultHeader = 0x180;
inline constexpr uint32_t kCobCommand = 0x200;
inline constexpr uint32_t kCobResultObject = 0x280;
inline constexpr uint32_t kCobResultEnd = 0x380;
inline constexpr uint32_t kCobCommandAck = 0x480;
inline constexpr uint32_t kCobHeartbeat = 0x700;

// Capacity of one result set: the object index has 6 bits in the object frames.
inline constexpr size_t kMaxResultObjects = 64;
inline constexpr size_t kObjectParts = 4;  // frames per object
// Header + 4 frames per object + end frame.
inline constexpr size_t kMaxResultFrames = 2 + kObjectParts * kMaxResultObjects;
inline constexpr uint8_t kMaxModelId = 31;  // model ids are bits of the 32-bit model mask

// Command limits (range-checked by EncodeCommand and DecodeCommand).
inline constexpr uint16_t kTimeBudgetMinMs = 20;
inline constexpr uint16_t kTimeBudgetMaxMs = 10000;
inline constexpr uint16_t kFreeRunRateMaxDeciHz = 300;  // 30.0 Hz; 0 = free-run off

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

Status CheckNodeId(uint8_t node_id);

// ---------------------------------------------------------------------------------------------
// NMT and heartbeat

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

// ---------------------------------------------------------------------------------------------
// Commands (0x200 + id). Byte 0 is the command code; arguments follow. Encoded frames are always
// 8 bytes (unused bytes 0); decoding accepts any length that holds the arguments.

// Code 0 is the idle value of the command RPDO: a PLC that clears its output after each command
// sends it ("on change"); it runs nothing, gets no ack and raises no EMCY.
inline constexpr uint8_t kCommandIdle = 0x00;

enum class CommandCode : uint8_t {
  kTrigger = 0x01,         // u16 request id (1..65535) at byte 1
  kSelectModels = 0x02,    // u32 model mask at byte 1 (non-zero; bit n = model id n)
  kSetTimeBudget = 0x03,   // u16 ms at byte 1 (kTimeBudgetMinMs..kTimeBudgetMaxMs)
  kClearFault = 0x04,      // no arguments
  kSetFreeRunRate = 0x05,  // u16 0.1 Hz at byte 1 (0 = off, ..kFreeRunRateMaxDeciHz)
};
const char* CommandName(CommandCode code);

struct Command {
  CommandCode code = CommandCode::kTrigger;
  uint16_t request_id = 0;         // kTrigger
  uint32_t model_mask = 0;         // kSelectModels
  uint16_t time_budget_ms = 0;     // kSetTimeBudget
  uint16_t free_run_rate_dhz = 0;  // kSetFreeRunRate, 0.1 Hz units
};

Result<CanFrame> EncodeCommand(const Command& command, uint8_t node_id);
// kInvalidArgument: wrong id, unknown command code, too short; kOutOfRange: argument outside
// its range. Every message names the command and the value.
Result<Command> DecodeCommand(const CanFrame& frame, uint8_t node_id);
// The mask may only name models that are loaded (ids 0..loaded_model_count-1).
Status CheckModelMask(uint32_t model_mask, size_t loaded_model_count);

// Command acknowledge (0x480 + id), 8 bytes: [code, status, request id u16, value u32].
// status is 0 for accepted, else the StatusCode number of the rejection. value echoes what was
// applied: the mask, the budget in ms, the rate in 0.1 Hz, 0 otherwise.
struct CommandAck {
  uint8_t command_code = 0;
  uint8_t status = 0;
  uint16_t request_id = 0;
  uint32_t value = 0;
};
Result<CanFrame> EncodeCommandAck(const CommandAck& ack, uint8_t node_id);
Result<CommandAck> DecodeCommandAck(const CanFrame& frame, uint8_t node_id);
// Ack for a decoded (accepted or rejected) command frame.
CommandAck MakeCommandAck(const CanFrame& command_frame, const Status& status);

// ---------------------------------------------------------------------------------------------
// Results

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

// Reassembles result sets from received frames (controller side; used by tests and as the
// reference for PLC implementations).
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

// ---------------------------------------------------------------------------------------------
// EMCY (0x080 + id), 8 bytes: [error code u16, error register u8, firmware state u8, detail u32]

enum class EmcyCode : uint16_t {
  kNoError = 0x0000,  // sent after a fault is cleared (CANopen "error reset")
  kGeneric = 0x1000,
  kDeviceHardware = 0x5000,  // board fault (GPIO, memory)
  kSoftware = 0x6100,        // internal software error
  kDataSet = 0x6300,         // model tables missing or corrupt
  kSensor = 0x7300,          // camera: no frames, timeout, sync lost
  kCommunication = 0x8100,   // generic CAN communication problem
  kCanOverrun = 0x8110,      // received frames lost
  kCanErrorPassive = 0x8120,
  kRecoveredFromBusOff = 0x8140,
  kProtocolError = 0x8200,   // command rejected: unknown code or value out of range
  kPdoLengthError = 0x8210,  // command frame too short
  kRecording = 0xFF10,       // manufacturer-specific: a recorded pair could not be written
};

enum class FirmwareState : uint8_t {
  kInit = 0,
  kReady = 1,
  kBusy = 2,
  kFault = 3,
};

struct Emcy {
  uint16_t error_code = 0;
  uint8_t error_register = 0;  // CiA 301 object 0x1001 bits; ErrorRegisterFor() derives it
  FirmwareState state = FirmwareState::kInit;
  uint32_t detail = 0;  // manufacturer-specific, see MakeCommandRejectedEmcy
};

// CiA 301 error register: bit 0 generic (any error), bit 4 communication (0x8xxx),
// bit 7 manufacturer-specific (0x5000, 0x6xxx, 0x7xxx, 0xFFxx). 0 for kNoError.
uint8_t ErrorRegisterFor(uint16_t error_code);
Result<CanFrame> EncodeEmcy(const Emcy& emcy, uint8_t node_id);
Result<Emcy> DecodeEmcy(const CanFrame& frame, uint8_t node_id);
// EMCY answering a rejected command: code kPdoLengthError for a short frame, else
// kProtocolError; detail = command byte << 24 | StatusCode << 16 | bytes 1..2 of the command
// (the offending u16 argument, or the low half of a mask).
Emcy MakeCommandRejectedEmcy(const CanFrame& command_frame, const Status& status,
                             FirmwareState state);

}  // namespace sh::protocol
