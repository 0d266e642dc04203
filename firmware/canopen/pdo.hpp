// PDOs of the sensor: COB-IDs from the communication parameters (0x1400.., 0x1800..), frame
// layouts from the fixed mappings (0x1600.., 0x1A00..). A TPDO is packed from the current values
// of its mapped objects and an RPDO unpacked into them, so the frames on the bus are the
// mapping the manager reads, by construction.
//
//   TPDO1 result set header   TPDO2 stream object part   TPDO3 stream end   TPDO4 command ack
//   TPDO5..8 object answer (PDO mode)                     RPDO1 command      RPDO2 object request
//
// COB-ID writes (sub 1): bit 31 switches a PDO off and on. TPDO1..4 and the RPDOs keep their
// node-id based identifier; TPDO5..8 may be moved to another identifier while they are invalid
// (their default band 0x1C0..0x4C0 + node id is shared with nodes 64 ids away). Extended
// identifiers and the identifiers CiA 301 reserves are refused.
#pragma once

#include <cstdint>

#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/od_table.hpp"
#include "hal/can.hpp"
#include "recog/base/status.hpp"

namespace sh::canopen {

// PDO numbers, 0-based (TPDO1 = 0).
inline constexpr int kTpdoHeader = 0;
inline constexpr int kTpdoStreamObject = 1;
inline constexpr int kTpdoStreamEnd = 2;
inline constexpr int kTpdoAck = 3;
inline constexpr int kTpdoAnswerFirst = 4;  // TPDO5..8
inline constexpr int kTpdoAnswerCount = 4;
inline constexpr int kRpdoCommand = 0;
inline constexpr int kRpdoRequest = 1;

uint32_t TpdoCobId(const ObjectDictionary& od, int n);  // with the valid bit
uint32_t RpdoCobId(const ObjectDictionary& od, int n);
inline bool CobIdValid(uint32_t cob_id) { return (cob_id & kCobIdInvalid) == 0; }
inline uint32_t CanIdOf(uint32_t cob_id) { return cob_id & 0x7FF; }

// Bytes of PDO n's mapping.
size_t TpdoLength(const ObjectDictionary& od, int n);
size_t RpdoLength(const ObjectDictionary& od, int n);

// TPDO n from its mapped objects (whether valid or not). kInternal if a mapping names an
// absent entry (a table error, caught by the tests).
Status PackTpdo(const ObjectDictionary& od, int n, hal::CanFrame* out);

// The valid RPDO that listens on `frame`'s identifier, else -1.
int RpdoFor(const ObjectDictionary& od, const hal::CanFrame& frame);
// Stores RPDO n's mapped objects from `frame`. Every value is checked as a bus write first and
// nothing is stored if one fails. kLengthTooLow: the frame is shorter than the mapping (the
// caller answers EMCY 0x8210, CiA 301 "PDO not processed due to length error").
SdoAbort UnpackRpdo(ObjectDictionary* od, int n, const hal::CanFrame& frame);

// Result mode (0x2000 sub 4): sets the valid bits of TPDO2/3 (stream) and TPDO5..8 (answers).
void ApplyResultMode(ObjectDictionary* od, ResultMode mode);

// Whether a bus write of `value` to a PDO COB-ID entry is allowed (kNone) or its abort code.
// `entry` must be sub 1 of 0x1400.. or 0x1800...
SdoAbort CheckCobIdWrite(const OdEntry& entry, uint32_t value);
bool IsPdoCobIdEntry(const OdEntry& entry);

}  // namespace sh::canopen
