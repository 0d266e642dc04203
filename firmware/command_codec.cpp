#include "firmware/command_codec.hpp"

#include <cstdint>

#include "firmware/le_bytes.hpp"

namespace sh::protocol {
namespace {

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

}  // namespace

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
