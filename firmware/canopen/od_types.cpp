#include "firmware/canopen/od_types.hpp"

#include "firmware/canopen/od_table.hpp"

namespace sh::canopen {

size_t DataTypeSize(DataType type) {
  switch (type) {
    case DataType::kBoolean:
    case DataType::kInteger8:
    case DataType::kUnsigned8:
      return 1;
    case DataType::kInteger16:
    case DataType::kUnsigned16:
      return 2;
    case DataType::kInteger32:
    case DataType::kUnsigned32:
      return 4;
    case DataType::kVisibleString:
      return 0;
  }
  return 0;
}

bool IsSigned(DataType type) {
  return type == DataType::kInteger8 || type == DataType::kInteger16 ||
         type == DataType::kInteger32;
}

const char* DataTypeName(DataType type) {
  switch (type) {
    case DataType::kBoolean:
      return "BOOLEAN";
    case DataType::kInteger8:
      return "INTEGER8";
    case DataType::kInteger16:
      return "INTEGER16";
    case DataType::kInteger32:
      return "INTEGER32";
    case DataType::kUnsigned8:
      return "UNSIGNED8";
    case DataType::kUnsigned16:
      return "UNSIGNED16";
    case DataType::kUnsigned32:
      return "UNSIGNED32";
    case DataType::kVisibleString:
      return "VISIBLE_STRING";
  }
  return "unknown";
}

const char* AccessName(Access access) {
  switch (access) {
    case Access::kConst:
      return "const";
    case Access::kRo:
      return "ro";
    case Access::kRw:
      return "rw";
    case Access::kWo:
      return "wo";
  }
  return "ro";
}

const char* SdoAbortText(SdoAbort abort) {
  switch (abort) {
    case SdoAbort::kNone:
      return "no abort";
    case SdoAbort::kToggleBit:
      return "toggle bit not alternated";
    case SdoAbort::kTimeout:
      return "SDO protocol timed out";
    case SdoAbort::kCommandSpecifier:
      return "command specifier not valid or unknown";
    case SdoAbort::kUnsupportedAccess:
      return "unsupported access to an object";
    case SdoAbort::kWriteOnly:
      return "attempt to read a write-only object";
    case SdoAbort::kReadOnly:
      return "attempt to write a read-only object";
    case SdoAbort::kNoObject:
      return "object does not exist in the object dictionary";
    case SdoAbort::kLengthMismatch:
      return "length of service parameter does not match";
    case SdoAbort::kLengthTooHigh:
      return "length of service parameter too high";
    case SdoAbort::kLengthTooLow:
      return "length of service parameter too low";
    case SdoAbort::kNoSubIndex:
      return "sub-index does not exist";
    case SdoAbort::kInvalidValue:
      return "invalid value for parameter";
    case SdoAbort::kValueTooHigh:
      return "value of parameter written too high";
    case SdoAbort::kValueTooLow:
      return "value of parameter written too low";
    case SdoAbort::kGeneral:
      return "general error";
    case SdoAbort::kCannotStore:
      return "data cannot be transferred or stored to the application";
    case SdoAbort::kDeviceState:
      return "data cannot be transferred because of the present device state";
  }
  return "unknown abort code";
}

const char* OutputFrameName(OutputFrame frame) {
  switch (frame) {
    case OutputFrame::kCamera:
      return "camera";
    case OutputFrame::kTable:
      return "table";
    case OutputFrame::kRobotBase:
      return "robot_base";
    case OutputFrame::kRobotFlange:
      return "robot_flange";
  }
  return "unknown";
}

}  // namespace sh::canopen
