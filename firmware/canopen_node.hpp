// The firmware's CANopen slave: the object dictionary with its SDO server, LSS slave, error
// state (error register, EMCY sequence, error history) and the process data (last result set,
// PDO-mode answers), behind one lock so the core's threads can share it.
//
// The core keeps its own state machine and its frames (boot-up, heartbeat, commands, result
// stream); it hands every received frame to HandleFrame first, and reports faults, results,
// acks and settings here so the dictionary always reads what the device does. What a frame asks
// of the core (apply settings, run a command written by SDO, take a new node id) comes back in
// CanopenEvents, to be acted on after the call, outside the lock.
#pragma once

#include <cstdint>
#include <mutex>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/error_state.hpp"
#include "firmware/canopen/lss_slave.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/pdo.hpp"
#include "firmware/canopen/result_objects.hpp"
#include "firmware/canopen/sdo_server.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"
#include "recog/base/vector.hpp"

namespace sh::fw {

// Settings a manager may change by SDO (and the PLC by command).
struct CanopenSettings {
  uint16_t heartbeat_ms = 200;  // 0x1017
  uint16_t budget_ms = 1000;    // 0x2000 sub 1
  uint32_t model_mask = 0xFFFFFFFFu;
  uint16_t free_run_dhz = 0;
  canopen::ResultMode result_mode = canopen::ResultMode::kStream;
};

struct CanopenDeviceInfo {
  uint8_t node_id = 1;  // 1..127 or canopen::kNodeIdUnconfigured
  uint32_t serial_number = 0;
  const char* hardware_version = "";
  canopen::OutputFrame output_frame = canopen::OutputFrame::kCamera;
  canopen::LssStore* lss_store = nullptr;  // null: LSS store answers "not supported"
};

// What a received frame asks of the core.
struct CanopenEvents {
  bool settings_changed = false;   // read settings() and apply
  bool heartbeat_changed = false;  // 0x1017 written
  bool node_id_changed = false;    // LSS: an unconfigured node took new_node_id
  uint8_t new_node_id = 0;
  bool has_command = false;  // 0x2020 sub 1 written by SDO: run `command` like an RPDO1
  hal::CanFrame command;
  bool rpdo_length_error = false;  // an RPDO shorter than its mapping (EMCY 0x8210)
  uint32_t rpdo_detail = 0;
};

inline constexpr size_t kCanopenMaxReplies = 8;  // frames one received frame can cause

class CanopenNode final : private canopen::WriteHandler {
 public:
  CanopenNode();
  CanopenNode(const CanopenNode&) = delete;
  CanopenNode& operator=(const CanopenNode&) = delete;

  void Init(const CanopenDeviceInfo& info, const CanopenSettings& settings);

  // A received frame. SDO requests are served in pre-operational and operational, RPDO2 in
  // operational, LSS in every state. Replies are appended to `out`. true if the frame was for
  // the CANopen services (the core then ignores it).
  bool HandleFrame(const hal::CanFrame& frame, protocol::NmtState nmt, int64_t now_ns,
                   Vector<hal::CanFrame>& out, CanopenEvents* events);
  // SDO transfer timeouts: an abort frame to send, if any.
  bool Poll(int64_t now_ns, hal::CanFrame* abort);

  // NMT reset communication (also the LSS-pending node id) / reset node (also the settings):
  // returns the node id now in use.
  uint8_t ResetCommunication();
  uint8_t ResetNode(const CanopenSettings& power_on);
  uint8_t node_id() const;

  // Error conditions and events -> error register, history and the EMCY to send.
  canopen::EmcyMessage Raise(uint32_t bit, uint16_t code, uint32_t detail);
  bool ClearConditions(uint32_t bits, canopen::EmcyMessage* reset);
  void Event(uint16_t code, uint32_t detail, canopen::EmcyMessage* error,
             canopen::EmcyMessage* reset);
  uint8_t error_register() const;

  // Process data. StoreResult before the set's header goes out, so a PDO-mode request after the
  // header is answered from this set.
  Status StoreResult(const protocol::ResultSet& set, uint8_t crc);
  void StoreAck(const protocol::CommandAck& ack);
  void StoreCommand(const hal::CanFrame& command);  // last RPDO1 received (0x2020)
  void SetDeviceStatus(uint8_t firmware_state, uint32_t fault_causes);
  void SetModels(const char* const* names, size_t count);
  void SetSettings(const CanopenSettings& settings);  // after commands changed them
  CanopenSettings settings() const;

  // Whether TPDO n (0-based) is valid, and its CAN identifier.
  bool TpdoValid(int n) const;
  uint32_t TpdoCanId(int n) const;
  bool RpdoValid(int n) const;
  canopen::OutputFrame output_frame() const { return output_frame_; }

  // Read access for tests and diagnostics (under the lock).
  uint32_t Get(uint16_t index, uint8_t sub) const;

 private:
  canopen::SdoAbort OnWrite(const canopen::OdEntry& entry, uint32_t value) override;
  void AnswerRequest(uint8_t counter, uint8_t index, Vector<hal::CanFrame>& out);
  void WriteSettingsLocked(const CanopenSettings& s);

  mutable std::mutex mutex_;
  canopen::ObjectDictionary od_;
  canopen::SdoServer sdo_{&od_};
  canopen::LssSlave lss_;
  canopen::ErrorState errors_{&od_};
  canopen::ResultObjects results_{&od_};
  canopen::OutputFrame output_frame_ = canopen::OutputFrame::kCamera;
  size_t model_count_ = 0;
  uint8_t node_id_ = 1;
  uint16_t power_on_heartbeat_ms_ = 200;
  // Set by OnWrite during a frame's handling, returned through CanopenEvents.
  CanopenEvents* pending_ = nullptr;
  // The NMT state of the frame being handled: commands by SDO run only when operational.
  protocol::NmtState pending_nmt_ = protocol::NmtState::kPreOperational;
  Vector<hal::CanFrame>* pending_out_ = nullptr;
};

}  // namespace sh::fw
