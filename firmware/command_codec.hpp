// Commands from the PLC (0x200 + id, RPDO1) and their acknowledges (0x480 + id, TPDO4); the EMCY
// that answers a rejected command. Byte 0 of a command is the command code; arguments follow.
// Encoded frames are always 8 bytes (unused bytes 0); decoding accepts any length that holds the
// arguments.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/emcy.hpp"
#include "recog/base/status.hpp"

namespace sh::protocol {

// Command limits (range-checked by EncodeCommand and DecodeCommand).
inline constexpr uint16_t kTimeBudgetMinMs = 20;
inline constexpr uint16_t kTimeBudgetMaxMs = 10000;
inline constexpr uint16_t kFreeRunRateMaxDeciHz = 300;  // 30.0 Hz; 0 = free-run off

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

// EMCY answering a rejected command: code kPdoLengthError for a short frame, else
// kProtocolError; detail = command byte << 24 | StatusCode << 16 | bytes 1..2 of the command
// (the offending u16 argument, or the low half of a mask).
Emcy MakeCommandRejectedEmcy(const CanFrame& command_frame, const Status& status,
                             FirmwareState state);

}  // namespace sh::protocol
