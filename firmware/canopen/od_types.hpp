// Vocabulary of the CANopen object dictionary (CiA 301 section 7.4, CiA 306 for the EDS names):
// data types, access rights, object codes and the SDO abort codes the server answers with.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sh::canopen {

// Data types by their CiA 301 index in the dictionary (the number the EDS writes as DataType).
enum class DataType : uint16_t {
  kBoolean = 0x0001,
  kInteger8 = 0x0002,
  kInteger16 = 0x0003,
  kInteger32 = 0x0004,
  kUnsigned8 = 0x0005,
  kUnsigned16 = 0x0006,
  kUnsigned32 = 0x0007,
  kVisibleString = 0x0009,
};

// Bytes of a value of `type`; 0 for strings (their length is the string's).
size_t DataTypeSize(DataType type);
bool IsSigned(DataType type);
const char* DataTypeName(DataType type);

// Access as seen from the bus (SDO). `kConst` is read-only and never changes while the device
// runs; the device itself may update `kRo` values (error register, results).
enum class Access : uint8_t { kConst, kRo, kRw, kWo };
const char* AccessName(Access access);  // the EDS spelling: const, ro, rw, wo
inline bool Readable(Access a) { return a != Access::kWo; }
inline bool Writable(Access a) { return a == Access::kRw || a == Access::kWo; }

// CiA 301 object codes (EDS ObjectType).
enum class ObjectCode : uint8_t { kVar = 0x7, kArray = 0x8, kRecord = 0x9 };

// SDO abort codes (CiA 301 table 22), the ones this server can answer with.
enum class SdoAbort : uint32_t {
  kNone = 0,
  kToggleBit = 0x05030000,          // toggle bit not alternated
  kTimeout = 0x05040000,            // SDO protocol timed out
  kCommandSpecifier = 0x05040001,   // client/server command specifier not valid or unknown
  kUnsupportedAccess = 0x06010000,  // unsupported access to an object
  kWriteOnly = 0x06010001,          // attempt to read a write-only object
  kReadOnly = 0x06010002,           // attempt to write a read-only object
  kNoObject = 0x06020000,           // object does not exist in the object dictionary
  kLengthMismatch = 0x06070010,     // data type does not match, length does not match
  kLengthTooHigh = 0x06070012,      // data type does not match, length too high
  kLengthTooLow = 0x06070013,       // data type does not match, length too low
  kNoSubIndex = 0x06090011,         // sub-index does not exist
  kInvalidValue = 0x06090030,       // invalid value for parameter (download only)
  kValueTooHigh = 0x06090031,       // value of parameter written too high
  kValueTooLow = 0x06090032,        // value of parameter written too low
  kGeneral = 0x08000000,            // general error
  kCannotStore = 0x08000020,        // data cannot be transferred or stored to the application
  kDeviceState = 0x08000022,        // ... because of the present device state
};
const char* SdoAbortText(SdoAbort abort);

}  // namespace sh::canopen
