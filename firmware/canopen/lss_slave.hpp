// LSS slave (CiA 305, layer setting services): lets a manager find the sensor by its identity
// and set its node id from the bus, without a configuration file on the board.
//
// Requests on 0x7E5, responses on 0x7E4, 8 bytes each. Services:
//   0x04        switch state global (0 waiting, 1 configuration), no response
//   0x40..0x43  switch state selective by vendor, product, revision, serial -> 0x44
//   0x11        configure node id (1..127, or 0xFF = unconfigured)      -> 0x11 [error]
//   0x13        configure bit timing                                    -> 0x13 [1: not supported]
//   0x15        activate bit timing (ignored: the bit rate is the interface's, `ip link`)
//   0x17        store configuration (the pending node id, via LssStore) -> 0x17 [error]
//   0x5A..0x5D  inquire vendor, product, revision, serial               -> same cs, u32
//   0x5E        inquire node id                                         -> 0x5E [active id]
//   0x46..0x4B  identify remote slave by identity ranges                -> 0x4F
//   0x4C        identify non-configured remote slave                    -> 0x50
//   0x51        fastscan (non-configured slaves in waiting state)       -> 0x4F
// Configuration services are answered only in the configuration state.
//
// A configured node id is pending: it becomes active at the next NMT reset communication (or
// reset node), or at once when an unconfigured node leaves the configuration state (CiA 305).
// Pure and thread-free.
#pragma once

#include <cstdint>

#include "hal/can.hpp"
#include "recog/base/status.hpp"

namespace sh::canopen {

inline constexpr uint32_t kLssMasterCobId = 0x7E5;  // master -> slaves
inline constexpr uint32_t kLssSlaveCobId = 0x7E4;   // slave -> master
inline constexpr uint8_t kNodeIdUnconfigured = 0xFF;

struct LssIdentity {
  uint32_t vendor_id = 0;
  uint32_t product_code = 0;
  uint32_t revision = 0;
  uint32_t serial = 0;
};

// Non-volatile storage of the node id (the firmware writes a file).
class LssStore {
 public:
  virtual ~LssStore() = default;
  virtual Status StoreNodeId(uint8_t node_id) = 0;
};

enum class LssState : uint8_t { kWaiting, kConfiguration };

struct LssOutcome {
  bool respond = false;        // send *response
  bool apply_pending = false;  // make the pending node id active now (reset communication)
};

class LssSlave {
 public:
  LssSlave() = default;
  // active_node_id: 1..127 or kNodeIdUnconfigured. store may be null (store not supported).
  void Init(const LssIdentity& identity, uint8_t active_node_id, LssStore* store);

  LssOutcome Handle(const hal::CanFrame& request, hal::CanFrame* response);

  // The node id the device now uses (after a reset communication applied the pending one).
  void set_active_node_id(uint8_t id) { active_ = id; }
  uint8_t active_node_id() const { return active_; }
  uint8_t pending_node_id() const { return pending_; }
  LssState state() const { return state_; }
  const LssIdentity& identity() const { return identity_; }

 private:
  hal::CanFrame Response(uint8_t cs) const;
  bool Fastscan(const uint8_t* d);

  LssIdentity identity_;
  uint8_t active_ = 1;
  uint8_t pending_ = 1;
  LssStore* store_ = nullptr;
  LssState state_ = LssState::kWaiting;
  int selective_step_ = 0;  // switch state selective: parts matched so far
  // Identify remote slave: the next part expected (0 vendor .. 5 serial high), whether all parts
  // so far matched, and the low ends of the revision and serial ranges.
  int remote_step_ = 0;
  bool remote_match_ = false;
  uint32_t remote_revision_low_ = 0;
  uint32_t remote_serial_low_ = 0;
  uint8_t fastscan_pos_ = 0;  // LSSPos: identity part being scanned
};

}  // namespace sh::canopen
