// The object dictionary of the sensor, declared once: the runtime dictionary
// (object_dictionary.hpp), the SDO server, the PDO packer and the EDS file
// (eds_writer.hpp) are all generated from kOdTable. docs/can-protocol.md describes each object.
//
// A row either opens an object (Var, Record, Array) or declares a sub-entry of the object opened
// last (Sub). Var rows open a VAR object and declare its only entry, sub-index 0. Sub-index 0 of a
// RECORD or ARRAY ("highest sub-index supported", const) is added automatically unless a row
// declares it. A Record or Array with repeat n stands for n identical objects at index, index+1,
// ... index+n-1 (the per-object result records); a Sub with Repeat(n, first) stands for n entries
// at sub, sub+1, ... numbered first, first+1, ... in their names (array elements). Rows are in
// ascending (index, sub-index) order.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/od_types.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"

#ifndef STEREOHASH_VERSION_MAJOR
#define STEREOHASH_VERSION_MAJOR 0
#define STEREOHASH_VERSION_MINOR 0
#define STEREOHASH_VERSION "0.0.0"
#endif

namespace sh::canopen {

// ---------------------------------------------------------------------------------------------
// Identity (0x1018) and device information

// No CiA vendor id has been assigned to this design: 0 marks it as such. A product built from it
// enters its own vendor id here (the EDS and LSS identity follow).
inline constexpr uint32_t kVendorId = 0x00000000;
inline constexpr uint32_t kProductCode = 0x53480001;  // "SH", stereo vision sensor 1
// Revision: major version in the high word, minor in the low word (CiA 301 7.5.2.24).
inline constexpr uint32_t kRevisionNumber =
    static_cast<uint32_t>(STEREOHASH_VERSION_MAJOR) << 16 | STEREOHASH_VERSION_MINOR;
inline constexpr const char* kDeviceName = "stereohash";
inline constexpr const char* kSoftwareVersion = STEREOHASH_VERSION;

// ---------------------------------------------------------------------------------------------
// Indices the firmware uses by name

inline constexpr uint16_t kIdxDeviceType = 0x1000;
inline constexpr uint16_t kIdxErrorRegister = 0x1001;
inline constexpr uint16_t kIdxErrorHistory = 0x1003;
inline constexpr uint8_t kErrorHistoryDepth = 8;
inline constexpr uint16_t kIdxDeviceName = 0x1008;
inline constexpr uint16_t kIdxHardwareVersion = 0x1009;
inline constexpr uint16_t kIdxSoftwareVersion = 0x100A;
inline constexpr uint16_t kIdxEmcyCobId = 0x1014;
inline constexpr uint16_t kIdxHeartbeatTime = 0x1017;
inline constexpr uint16_t kIdxIdentity = 0x1018;
inline constexpr uint16_t kIdxSdoServer = 0x1200;
inline constexpr uint16_t kIdxRpdoComm = 0x1400;  // + n for RPDO n+1
inline constexpr uint16_t kIdxRpdoMap = 0x1600;
inline constexpr uint16_t kIdxTpdoComm = 0x1800;  // + n for TPDO n+1
inline constexpr uint16_t kIdxTpdoMap = 0x1A00;
inline constexpr int kRpdoCount = 2;
inline constexpr int kTpdoCount = 8;

inline constexpr uint16_t kIdxSettings = 0x2000;
inline constexpr uint8_t kSubBudget = 1, kSubModelMask = 2, kSubFreeRunRate = 3, kSubResultMode = 4,
                         kSubOutputFrame = 5;
inline constexpr uint16_t kIdxModelNames = 0x2001;
inline constexpr uint16_t kIdxModelCount = 0x2002;
inline constexpr uint16_t kIdxObjectRequest = 0x2010;  // RPDO2
inline constexpr uint8_t kSubRequestCounter = 1, kSubRequestIndex = 2;
inline constexpr uint16_t kIdxObjectAnswer = 0x2011;  // TPDO5..8
inline constexpr uint8_t kSubAnswerCounter = 1, kSubAnswerIndex = 2, kSubAnswerStatus = 3,
                         kSubAnswerModel = 4, kSubAnswerInstance = 5, kSubAnswerSequence = 6,
                         kSubAnswerScore = 7, kSubAnswerX = 8, kSubAnswerY = 9, kSubAnswerZ = 10,
                         kSubAnswerQw = 11, kSubAnswerQx = 12, kSubAnswerQy = 13, kSubAnswerQz = 14,
                         kSubAnswerCount = 15, kSubAnswerFrame = 16;
inline constexpr uint16_t kIdxCommand = 0x2020;  // RPDO1
inline constexpr uint8_t kSubCommandCode = 1, kSubCommandArgument = 2;
inline constexpr uint16_t kIdxCommandAck = 0x2021;  // TPDO4
inline constexpr uint16_t kIdxDeviceStatus = 0x2030;
inline constexpr uint8_t kSubFirmwareState = 1, kSubFaultCauses = 2;
inline constexpr uint16_t kIdxResultSet = 0x2100;  // TPDO1 and TPDO3
inline constexpr uint8_t kSubSetSequence = 1, kSubSetCount = 2, kSubSetStatus = 3, kSubSetTime = 4,
                         kSubSetRequestId = 5, kSubSetFrame = 6, kSubSetCrc = 7;
inline constexpr uint16_t kIdxStreamFrame = 0x2101;   // TPDO2 layout
inline constexpr uint16_t kIdxResultObject = 0x2200;  // + object index, 0..63
inline constexpr uint8_t kSubObjModel = 1, kSubObjInstance = 2, kSubObjScore = 3, kSubObjX = 4,
                         kSubObjY = 5, kSubObjZ = 6, kSubObjQw = 7, kSubObjQx = 8, kSubObjQy = 9,
                         kSubObjQz = 10;
inline constexpr uint8_t kMaxModelNames = 32;  // model ids 0..31 (bits of the model mask)

// Result modes (0x2000 sub 4): which result PDOs are valid.
enum class ResultMode : uint8_t {
  kStream = 0,  // TPDO2/3: the multiplexed stream (the fast mode)
  kPdo = 1,     // TPDO5..8: one object per request (RPDO2), fits a PDO image
  kBoth = 2,    // both (commissioning: a PLC maps the PDOs while a logger records the stream)
};

// Frame the poses are reported in (0x2000 sub 5, 0x2100 sub 6, end frame byte 4): the left
// camera, the table (conveyor), the robot base (cameras fixed in the cell, eye-to-hand) or the
// robot flange (cameras on the robot, eye-in-hand: the robot multiplies with its flange pose at
// the time of the trigger).
enum class OutputFrame : uint8_t { kCamera = 0, kTable = 1, kRobotBase = 2, kRobotFlange = 3 };
const char* OutputFrameName(OutputFrame frame);

// COB-ID bits of the PDO communication parameters (CiA 301 7.5.2.35).
inline constexpr uint32_t kCobIdInvalid = 0x80000000u;  // PDO does not exist / not valid
inline constexpr uint32_t kCobIdNoRtr = 0x40000000u;    // no remote transmission
inline constexpr uint32_t kCobIdExtended = 0x20000000u;

// PDO mapping entry: index << 16 | sub-index << 8 | length in bits.
constexpr uint32_t Map(uint16_t index, uint8_t sub, uint8_t bits) {
  return static_cast<uint32_t>(index) << 16 | static_cast<uint32_t>(sub) << 8 | bits;
}

// ---------------------------------------------------------------------------------------------
// Rows

struct OdRow {
  bool opens_object = false;
  ObjectCode code = ObjectCode::kVar;
  uint16_t index = 0;
  uint8_t sub = 0;
  uint8_t repeat = 1;  // object rows: number of consecutive identical objects
  const char* name = "";
  DataType type = DataType::kUnsigned8;
  Access access = Access::kRo;
  bool pdo = false;               // may be mapped into a PDO
  int64_t value = 0;              // default; + node id when node_id_relative
  bool node_id_relative = false;  // EDS writes $NODEID+value
  bool has_limits = false;
  int64_t low = 0, high = 0;
  const char* text = nullptr;  // default of a VISIBLE_STRING
  uint8_t sub_repeat = 1;      // Sub rows: entries at sub .. sub + sub_repeat - 1
  uint8_t number_from = 0;     // their names end in number_from, number_from + 1, ...
  // Read-only, but a write of the value it holds is confirmed: configuration tools write the
  // PDO transmission type they read from the EDS, and an abort would fail their whole setup.
  bool same_value_writable = false;

  constexpr OdRow Pdo() const {
    OdRow r = *this;
    r.pdo = true;
    return r;
  }
  constexpr OdRow Limits(int64_t lo, int64_t hi) const {
    OdRow r = *this;
    r.has_limits = true;
    r.low = lo;
    r.high = hi;
    return r;
  }
  constexpr OdRow PlusNodeId() const {
    OdRow r = *this;
    r.node_id_relative = true;
    return r;
  }
  constexpr OdRow Repeat(uint8_t n, uint8_t first_number) const {
    OdRow r = *this;
    r.sub_repeat = n;
    r.number_from = first_number;
    return r;
  }
  constexpr OdRow SameValueWritable() const {
    OdRow r = *this;
    r.same_value_writable = true;
    return r;
  }
  constexpr OdRow Text(const char* t) const {
    OdRow r = *this;
    r.text = t;
    return r;
  }
};

constexpr OdRow Var(uint16_t index, const char* name, DataType type, Access access,
                    int64_t value = 0) {
  OdRow r;
  r.opens_object = true;
  r.code = ObjectCode::kVar;
  r.index = index;
  r.name = name;
  r.type = type;
  r.access = access;
  r.value = value;
  return r;
}
constexpr OdRow Object(ObjectCode code, uint16_t index, const char* name, uint8_t repeat = 1) {
  OdRow r;
  r.opens_object = true;
  r.code = code;
  r.index = index;
  r.repeat = repeat;
  r.name = name;
  return r;
}
constexpr OdRow Record(uint16_t index, const char* name, uint8_t repeat = 1) {
  return Object(ObjectCode::kRecord, index, name, repeat);
}
constexpr OdRow Array(uint16_t index, const char* name) {
  return Object(ObjectCode::kArray, index, name);
}
constexpr OdRow Sub(uint16_t index, uint8_t sub, const char* name, DataType type, Access access,
                    int64_t value = 0) {
  OdRow r;
  r.index = index;
  r.sub = sub;
  r.name = name;
  r.type = type;
  r.access = access;
  r.value = value;
  return r;
}

namespace od_rows {
using DT = DataType;
using AC = Access;
constexpr DT U8 = DT::kUnsigned8, U16 = DT::kUnsigned16, U32 = DT::kUnsigned32,
             I16 = DT::kInteger16, I32 = DT::kInteger32, VS = DT::kVisibleString;
constexpr AC CO = AC::kConst, RO = AC::kRo, RW = AC::kRw;

// Communication parameter of a PDO: COB-ID (+ node id) and transmission type 0xFE (event-driven,
// sent when the device has new data).
#define SH_OD_PDO_COMM(idx, what, cob_id, cob_access)                            \
  Record(idx, what " communication parameter"),                                  \
      Sub(idx, 1, "COB-ID used by " what, U32, cob_access, cob_id).PlusNodeId(), \
      Sub(idx, 2, "Transmission type", U8, RO, 0xFE).SameValueWritable()

inline constexpr OdRow kOdTable[] = {
    Var(0x1000, "Device type", U32, RO, 0),  // no CiA device profile: manufacturer-specific
    Var(0x1001, "Error register", U8, RO).Pdo(),
    Array(0x1003, "Pre-defined error field"),
    Sub(0x1003, 0, "Number of errors", U8, RW, 0).Limits(0, kErrorHistoryDepth),
    Sub(0x1003, 1, "Standard error field", U32, RO).Repeat(kErrorHistoryDepth, 1),
    Var(0x1008, "Manufacturer device name", VS, CO).Text(kDeviceName),
    Var(0x1009, "Manufacturer hardware version", VS, RO).Text(""),  // board or simulator
    Var(0x100A, "Manufacturer software version", VS, CO).Text(kSoftwareVersion),
    Var(0x1014, "COB-ID EMCY", U32, RO, 0x80).PlusNodeId(),
    // 0 = no heartbeat; 1..9 ms are refused (a heartbeat faster than 10 ms floods the bus).
    Var(0x1017, "Producer heartbeat time", U16, RW, 200).Limits(0, 10000),
    Record(0x1018, "Identity object"),
    Sub(0x1018, 1, "Vendor-ID", U32, RO, kVendorId),
    Sub(0x1018, 2, "Product code", U32, RO, kProductCode),
    Sub(0x1018, 3, "Revision number", U32, RO, kRevisionNumber),
    Sub(0x1018, 4, "Serial number", U32, RO, 0),
    Record(0x1200, "SDO server parameter"),
    Sub(0x1200, 1, "COB-ID client to server (rx)", U32, RO, 0x600).PlusNodeId(),
    Sub(0x1200, 2, "COB-ID server to client (tx)", U32, RO, 0x580).PlusNodeId(),
    SH_OD_PDO_COMM(0x1400, "RPDO1", 0x200, RW),  // command
    SH_OD_PDO_COMM(0x1401, "RPDO2", 0x300, RW),  // object request (PDO mode)
    Record(0x1600, "RPDO1 mapping parameter"),
    Sub(0x1600, 0, "Number of mapped objects", U8, CO, 2),
    Sub(0x1600, 1, "Mapped object 1", U32, CO, Map(0x2020, 1, 8)),
    Sub(0x1600, 2, "Mapped object 2", U32, CO, Map(0x2020, 2, 32)),
    Record(0x1601, "RPDO2 mapping parameter"),
    Sub(0x1601, 0, "Number of mapped objects", U8, CO, 2),
    Sub(0x1601, 1, "Mapped object 1", U32, CO, Map(0x2010, 1, 8)),
    Sub(0x1601, 2, "Mapped object 2", U32, CO, Map(0x2010, 2, 8)),
    SH_OD_PDO_COMM(0x1800, "TPDO1", 0x180, RW),  // result set header
    SH_OD_PDO_COMM(0x1801, "TPDO2", 0x280, RW),  // stream: object parts (multiplexed)
    SH_OD_PDO_COMM(0x1802, "TPDO3", 0x380, RW),  // stream: end of set
    SH_OD_PDO_COMM(0x1803, "TPDO4", 0x480, RW),  // command acknowledge
    // PDO mode: the answer to an object request. Invalid in the default stream mode; the 0x1C0
    // band is TPDO1 of node id + 64, so these COB-IDs may be moved while the PDO is invalid.
    SH_OD_PDO_COMM(0x1804, "TPDO5", kCobIdInvalid | 0x1C0, RW),
    SH_OD_PDO_COMM(0x1805, "TPDO6", kCobIdInvalid | 0x2C0, RW),
    SH_OD_PDO_COMM(0x1806, "TPDO7", kCobIdInvalid | 0x3C0, RW),
    SH_OD_PDO_COMM(0x1807, "TPDO8", kCobIdInvalid | 0x4C0, RW),
    Record(0x1A00, "TPDO1 mapping parameter"),
    Sub(0x1A00, 0, "Number of mapped objects", U8, CO, 5),
    Sub(0x1A00, 1, "Mapped object 1", U32, CO, Map(0x2100, 1, 16)),
    Sub(0x1A00, 2, "Mapped object 2", U32, CO, Map(0x2100, 2, 8)),
    Sub(0x1A00, 3, "Mapped object 3", U32, CO, Map(0x2100, 3, 8)),
    Sub(0x1A00, 4, "Mapped object 4", U32, CO, Map(0x2100, 4, 16)),
    Sub(0x1A00, 5, "Mapped object 5", U32, CO, Map(0x2100, 5, 16)),
    Record(0x1A01, "TPDO2 mapping parameter"),
    Sub(0x1A01, 0, "Number of mapped objects", U8, CO, 4),
    Sub(0x1A01, 1, "Mapped object 1", U32, CO, Map(0x2101, 1, 8)),
    Sub(0x1A01, 2, "Mapped object 2", U32, CO, Map(0x2101, 2, 8)),
    Sub(0x1A01, 3, "Mapped object 3", U32, CO, Map(0x2101, 3, 32)),
    Sub(0x1A01, 4, "Mapped object 4", U32, CO, Map(0x2101, 4, 16)),
    Record(0x1A02, "TPDO3 mapping parameter"),
    Sub(0x1A02, 0, "Number of mapped objects", U8, CO, 4),
    Sub(0x1A02, 1, "Mapped object 1", U32, CO, Map(0x2100, 1, 16)),
    Sub(0x1A02, 2, "Mapped object 2", U32, CO, Map(0x2100, 2, 8)),
    Sub(0x1A02, 3, "Mapped object 3", U32, CO, Map(0x2100, 7, 8)),
    Sub(0x1A02, 4, "Mapped object 4", U32, CO, Map(0x2100, 6, 8)),
    Record(0x1A03, "TPDO4 mapping parameter"),
    Sub(0x1A03, 0, "Number of mapped objects", U8, CO, 4),
    Sub(0x1A03, 1, "Mapped object 1", U32, CO, Map(0x2021, 1, 8)),
    Sub(0x1A03, 2, "Mapped object 2", U32, CO, Map(0x2021, 2, 8)),
    Sub(0x1A03, 3, "Mapped object 3", U32, CO, Map(0x2021, 3, 16)),
    Sub(0x1A03, 4, "Mapped object 4", U32, CO, Map(0x2021, 4, 32)),
    Record(0x1A04, "TPDO5 mapping parameter"),
    Sub(0x1A04, 0, "Number of mapped objects", U8, CO, 7),
    Sub(0x1A04, 1, "Mapped object 1", U32, CO, Map(0x2011, 1, 8)),
    Sub(0x1A04, 2, "Mapped object 2", U32, CO, Map(0x2011, 2, 8)),
    Sub(0x1A04, 3, "Mapped object 3", U32, CO, Map(0x2011, 3, 8)),
    Sub(0x1A04, 4, "Mapped object 4", U32, CO, Map(0x2011, 4, 8)),
    Sub(0x1A04, 5, "Mapped object 5", U32, CO, Map(0x2011, 5, 8)),
    Sub(0x1A04, 6, "Mapped object 6", U32, CO, Map(0x2011, 6, 8)),
    Sub(0x1A04, 7, "Mapped object 7", U32, CO, Map(0x2011, 7, 16)),
    Record(0x1A05, "TPDO6 mapping parameter"),
    Sub(0x1A05, 0, "Number of mapped objects", U8, CO, 2),
    Sub(0x1A05, 1, "Mapped object 1", U32, CO, Map(0x2011, 8, 32)),
    Sub(0x1A05, 2, "Mapped object 2", U32, CO, Map(0x2011, 9, 32)),
    Record(0x1A06, "TPDO7 mapping parameter"),
    Sub(0x1A06, 0, "Number of mapped objects", U8, CO, 3),
    Sub(0x1A06, 1, "Mapped object 1", U32, CO, Map(0x2011, 10, 32)),
    Sub(0x1A06, 2, "Mapped object 2", U32, CO, Map(0x2011, 11, 16)),
    Sub(0x1A06, 3, "Mapped object 3", U32, CO, Map(0x2011, 12, 16)),
    Record(0x1A07, "TPDO8 mapping parameter"),
    Sub(0x1A07, 0, "Number of mapped objects", U8, CO, 5),
    Sub(0x1A07, 1, "Mapped object 1", U32, CO, Map(0x2011, 13, 16)),
    Sub(0x1A07, 2, "Mapped object 2", U32, CO, Map(0x2011, 14, 16)),
    Sub(0x1A07, 3, "Mapped object 3", U32, CO, Map(0x2011, 15, 8)),
    Sub(0x1A07, 4, "Mapped object 4", U32, CO, Map(0x2011, 16, 8)),
    Sub(0x1A07, 5, "Mapped object 5", U32, CO, Map(0x2011, 1, 8)),

    Record(0x2000, "Settings"),
    Sub(0x2000, 1, "Time budget ms", U16, RW, 1000)
        .Limits(protocol::kTimeBudgetMinMs, protocol::kTimeBudgetMaxMs),
    Sub(0x2000, 2, "Model mask", U32, RW, 0xFFFFFFFF),
    Sub(0x2000, 3, "Free-run rate 0.1 Hz", U16, RW, 0).Limits(0, protocol::kFreeRunRateMaxDeciHz),
    Sub(0x2000, 4, "Result mode", U8, RW, 0).Limits(0, 2),
    Sub(0x2000, 5, "Output frame", U8, RO, 0).Limits(0, protocol::kMaxOutputFrame),
    Array(0x2001, "Model names"),
    Sub(0x2001, 1, "Model", VS, RO).Text("").Repeat(kMaxModelNames, 0),  // name of model id n
    Var(0x2002, "Loaded model count", U8, RO, 0),
    Record(0x2010, "Object request"),
    Sub(0x2010, 1, "Request counter", U8, RW).Pdo(),
    Sub(0x2010, 2, "Object index", U8, RW).Pdo(),
    Record(0x2011, "Object answer"),
    Sub(0x2011, 1, "Answer counter", U8, RO).Pdo(),
    Sub(0x2011, 2, "Object index", U8, RO).Pdo(),
    Sub(0x2011, 3, "Answer status", U8, RO).Pdo(),
    Sub(0x2011, 4, "Model id", U8, RO).Pdo(),
    Sub(0x2011, 5, "Instance", U8, RO).Pdo(),
    Sub(0x2011, 6, "Set sequence low byte", U8, RO).Pdo(),
    Sub(0x2011, 7, "Score 0.0001", U16, RO).Pdo(),
    Sub(0x2011, 8, "Position x 0.01 mm", I32, RO).Pdo(),
    Sub(0x2011, 9, "Position y 0.01 mm", I32, RO).Pdo(),
    Sub(0x2011, 10, "Position z 0.01 mm", I32, RO).Pdo(),
    Sub(0x2011, 11, "Quaternion w Q14", I16, RO).Pdo(),
    Sub(0x2011, 12, "Quaternion x Q14", I16, RO).Pdo(),
    Sub(0x2011, 13, "Quaternion y Q14", I16, RO).Pdo(),
    Sub(0x2011, 14, "Quaternion z Q14", I16, RO).Pdo(),
    Sub(0x2011, 15, "Set object count", U8, RO).Pdo(),
    Sub(0x2011, 16, "Output frame", U8, RO).Pdo(),
    Record(0x2020, "Command"),
    Sub(0x2020, 1, "Command code", U8, RW).Pdo(),
    Sub(0x2020, 2, "Command argument", U32, RW).Pdo(),
    Record(0x2021, "Command acknowledge"),
    Sub(0x2021, 1, "Command code", U8, RO).Pdo(),
    Sub(0x2021, 2, "Status", U8, RO).Pdo(),
    Sub(0x2021, 3, "Request id", U16, RO).Pdo(),
    Sub(0x2021, 4, "Value", U32, RO).Pdo(),
    Record(0x2030, "Device status"),
    Sub(0x2030, 1, "Firmware state", U8, RO).Pdo(),
    Sub(0x2030, 2, "Fault causes", U32, RO),
    Record(0x2100, "Result set"),
    Sub(0x2100, 1, "Sequence", U16, RO).Pdo(),
    Sub(0x2100, 2, "Object count", U8, RO).Pdo(),
    Sub(0x2100, 3, "Status", U8, RO).Pdo(),
    Sub(0x2100, 4, "Processing time 0.1 ms", U16, RO).Pdo(),
    Sub(0x2100, 5, "Request id", U16, RO).Pdo(),
    Sub(0x2100, 6, "Output frame", U8, RO).Pdo(),
    Sub(0x2100, 7, "CRC-8", U8, RO).Pdo(),
    // The stream's object frames are multiplexed (4 parts per object): this record only
    // describes their layout for the mapping; the values are in the result objects 0x2200...
    Record(0x2101, "Stream object frame"),
    Sub(0x2101, 1, "Sequence low byte", U8, RO).Pdo(),
    Sub(0x2101, 2, "Part and object index", U8, RO).Pdo(),
    Sub(0x2101, 3, "Part bytes 2-5", U32, RO).Pdo(),
    Sub(0x2101, 4, "Part bytes 6-7", U16, RO).Pdo(),
    Record(0x2200, "Result object", protocol::kMaxResultObjects),
    Sub(0x2200, 1, "Model id", U8, RO),
    Sub(0x2200, 2, "Instance", U8, RO),
    Sub(0x2200, 3, "Score 0.0001", U16, RO),
    Sub(0x2200, 4, "Position x 0.01 mm", I32, RO),
    Sub(0x2200, 5, "Position y 0.01 mm", I32, RO),
    Sub(0x2200, 6, "Position z 0.01 mm", I32, RO),
    Sub(0x2200, 7, "Quaternion w Q14", I16, RO),
    Sub(0x2200, 8, "Quaternion x Q14", I16, RO),
    Sub(0x2200, 9, "Quaternion y Q14", I16, RO),
    Sub(0x2200, 10, "Quaternion z Q14", I16, RO),
};
#undef SH_OD_PDO_COMM
}  // namespace od_rows

using od_rows::kOdTable;
inline constexpr size_t kOdRowCount = sizeof(kOdTable) / sizeof(kOdTable[0]);

// Entries of the dictionary (repeated objects expanded, automatic sub-index 0 included).
constexpr size_t CountOdEntries() {
  size_t total = 0;
  size_t r = 0;
  while (r < kOdRowCount) {
    const OdRow& obj = kOdTable[r];
    size_t subs = obj.code == ObjectCode::kVar ? 1 : 0;
    bool has_sub0 = obj.code == ObjectCode::kVar;
    size_t next = r + 1;
    while (next < kOdRowCount && !kOdTable[next].opens_object) {
      if (kOdTable[next].sub == 0) has_sub0 = true;
      subs += kOdTable[next].sub_repeat;
      ++next;
    }
    if (!has_sub0) ++subs;
    total += subs * obj.repeat;
    r = next;
  }
  return total;
}
inline constexpr size_t kOdEntryCount = CountOdEntries();
// Capacity of the runtime dictionary; a table that outgrows it does not compile.
inline constexpr size_t kMaxOdEntries = 1024;
static_assert(kOdEntryCount <= kMaxOdEntries, "object dictionary outgrew kMaxOdEntries");

// VISIBLE_STRING entries (each has its own fixed buffer).
constexpr size_t CountOdStrings() {
  size_t total = 0;
  uint8_t repeat = 1;
  for (const OdRow& row : kOdTable) {
    if (row.opens_object) repeat = row.repeat;
    if (row.type == DataType::kVisibleString &&
        (row.code == ObjectCode::kVar || !row.opens_object)) {
      total += repeat;
    }
  }
  return total;
}
inline constexpr size_t kMaxOdStrings = 64;
static_assert(CountOdStrings() <= kMaxOdStrings, "object dictionary outgrew kMaxOdStrings");

}  // namespace sh::canopen
