#include "firmware/canopen/lss_slave.hpp"

#include "firmware/le_bytes.hpp"

namespace sh::canopen {
namespace {

using protocol::GetU32;
using protocol::PutU32;

// Command specifiers (byte 0).
constexpr uint8_t kSwitchGlobal = 0x04;
constexpr uint8_t kConfigureNodeId = 0x11;
constexpr uint8_t kConfigureBitTiming = 0x13;
constexpr uint8_t kActivateBitTiming = 0x15;
constexpr uint8_t kStoreConfiguration = 0x17;
constexpr uint8_t kSwitchSelectiveVendor = 0x40;
constexpr uint8_t kSwitchSelectiveSerial = 0x43;
constexpr uint8_t kSwitchSelectiveResponse = 0x44;
constexpr uint8_t kIdentifyVendor = 0x46;
constexpr uint8_t kIdentifySerialHigh = 0x4B;
constexpr uint8_t kIdentifyNonConfigured = 0x4C;
constexpr uint8_t kIdentifySlaveResponse = 0x4F;
constexpr uint8_t kIdentifyNonConfiguredResponse = 0x50;
constexpr uint8_t kFastscan = 0x51;
constexpr uint8_t kInquireVendor = 0x5A;
constexpr uint8_t kInquireSerial = 0x5D;
constexpr uint8_t kInquireNodeId = 0x5E;

// Error codes of the configure/store responses.
constexpr uint8_t kLssOk = 0;
constexpr uint8_t kLssNodeIdOutOfRange = 1;
constexpr uint8_t kLssBitTimingNotSupported = 1;
constexpr uint8_t kLssStoreNotSupported = 1;
constexpr uint8_t kLssStoreAccessError = 2;

bool ValidNodeId(uint8_t id) { return id >= 1 && id <= 127; }

}  // namespace

void LssSlave::Init(const LssIdentity& identity, uint8_t active_node_id, LssStore* store) {
  identity_ = identity;
  active_ = active_node_id;
  pending_ = active_node_id;
  store_ = store;
  state_ = LssState::kWaiting;
  selective_step_ = 0;
  remote_step_ = 0;
  remote_match_ = false;
  fastscan_pos_ = 0;
}

hal::CanFrame LssSlave::Response(uint8_t cs) const {
  hal::CanFrame f;
  f.id = kLssSlaveCobId;
  f.len = 8;
  f.data[0] = cs;
  return f;
}

LssOutcome LssSlave::Handle(const hal::CanFrame& request, hal::CanFrame* response) {
  LssOutcome out;
  if (request.id != kLssMasterCobId || request.extended || request.rtr || request.error ||
      request.len < 1) {
    return out;
  }
  // LSS frames carry 8 bytes; shorter ones are padded with zeros rather than refused, so a
  // master that trims unused bytes still works.
  uint8_t d[8] = {};
  for (uint8_t i = 0; i < request.len && i < 8; ++i) d[i] = request.data[i];
  const uint8_t cs = d[0];
  const bool configuring = state_ == LssState::kConfiguration;

  if (cs == kSwitchGlobal) {
    if (d[1] == 1) {
      state_ = LssState::kConfiguration;
    } else if (d[1] == 0) {
      const bool leave = configuring;
      state_ = LssState::kWaiting;
      // An unconfigured node takes a newly configured id as soon as configuration ends.
      out.apply_pending = leave && active_ == kNodeIdUnconfigured && ValidNodeId(pending_);
    }
    selective_step_ = 0;
    return out;
  }
  if (cs >= kSwitchSelectiveVendor && cs <= kSwitchSelectiveSerial) {
    const int part = cs - kSwitchSelectiveVendor;
    const uint32_t own[4] = {identity_.vendor_id, identity_.product_code, identity_.revision,
                             identity_.serial};
    if (state_ != LssState::kWaiting) return out;
    if (part != selective_step_ || GetU32(&d[1]) != own[part]) {
      selective_step_ = part == 0 && GetU32(&d[1]) == own[0] ? 1 : 0;
      return out;
    }
    ++selective_step_;
    if (selective_step_ == 4) {
      selective_step_ = 0;
      state_ = LssState::kConfiguration;
      *response = Response(kSwitchSelectiveResponse);
      out.respond = true;
    }
    return out;
  }
  if (cs >= kIdentifyVendor && cs <= kIdentifySerialHigh) {
    const int part = cs - kIdentifyVendor;
    const uint32_t v = GetU32(&d[1]);
    if (part == 0) {
      remote_step_ = 1;
      remote_match_ = v == identity_.vendor_id;
      return out;
    }
    if (part != remote_step_) {
      remote_step_ = 0;
      return out;
    }
    ++remote_step_;
    switch (part) {
      case 1:
        remote_match_ = remote_match_ && v == identity_.product_code;
        break;
      case 2:
        remote_revision_low_ = v;
        break;
      case 3:
        remote_match_ =
            remote_match_ && identity_.revision >= remote_revision_low_ && identity_.revision <= v;
        break;
      case 4:
        remote_serial_low_ = v;
        break;
      default:
        remote_match_ =
            remote_match_ && identity_.serial >= remote_serial_low_ && identity_.serial <= v;
        remote_step_ = 0;
        if (remote_match_) {
          *response = Response(kIdentifySlaveResponse);
          out.respond = true;
        }
        break;
    }
    return out;
  }
  if (cs == kIdentifyNonConfigured) {
    if (active_ == kNodeIdUnconfigured && pending_ == kNodeIdUnconfigured) {
      *response = Response(kIdentifyNonConfiguredResponse);
      out.respond = true;
    }
    return out;
  }
  if (cs == kFastscan) {
    if (Fastscan(d)) {
      *response = Response(kIdentifySlaveResponse);
      out.respond = true;
    }
    return out;
  }

  if (!configuring) return out;  // the remaining services need the configuration state
  switch (cs) {
    case kConfigureNodeId: {
      *response = Response(kConfigureNodeId);
      if (ValidNodeId(d[1]) || d[1] == kNodeIdUnconfigured) {
        pending_ = d[1];
        response->data[1] = kLssOk;
      } else {
        response->data[1] = kLssNodeIdOutOfRange;
      }
      out.respond = true;
      return out;
    }
    case kConfigureBitTiming:
      *response = Response(kConfigureBitTiming);
      response->data[1] = kLssBitTimingNotSupported;
      out.respond = true;
      return out;
    case kActivateBitTiming:
      return out;
    case kStoreConfiguration: {
      *response = Response(kStoreConfiguration);
      if (store_ == nullptr) {
        response->data[1] = kLssStoreNotSupported;
      } else {
        response->data[1] = store_->StoreNodeId(pending_).ok() ? kLssOk : kLssStoreAccessError;
      }
      out.respond = true;
      return out;
    }
    case kInquireNodeId:
      *response = Response(kInquireNodeId);
      response->data[1] = active_;
      out.respond = true;
      return out;
    default:
      break;
  }
  if (cs >= kInquireVendor && cs <= kInquireSerial) {
    const uint32_t own[4] = {identity_.vendor_id, identity_.product_code, identity_.revision,
                             identity_.serial};
    *response = Response(cs);
    PutU32(&response->data[1], own[cs - kInquireVendor]);
    out.respond = true;
  }
  return out;
}

// CiA 305 fastscan: the master finds the identity of a non-configured slave bit by bit. byte 1..4
// IDNumber, byte 5 BitChecked (0x80 = reset), byte 6 LSSSub (part compared), byte 7 LSSNext.
bool LssSlave::Fastscan(const uint8_t* d) {
  if (state_ != LssState::kWaiting || active_ != kNodeIdUnconfigured) return false;
  const uint32_t id_number = GetU32(&d[1]);
  const uint8_t bit_checked = d[5];
  const uint8_t sub = d[6];
  const uint8_t next = d[7];
  if (bit_checked == 0x80) {
    fastscan_pos_ = 0;
    return true;
  }
  if (bit_checked > 31 || sub > 3 || next > 3 || sub != fastscan_pos_) return false;
  const uint32_t own[4] = {identity_.vendor_id, identity_.product_code, identity_.revision,
                           identity_.serial};
  // Bits bit_checked..31 must agree.
  const uint32_t mask = bit_checked == 0 ? 0xFFFFFFFFu : ~((1u << bit_checked) - 1);
  if (((id_number ^ own[sub]) & mask) != 0) return false;
  if (bit_checked == 0) {
    fastscan_pos_ = next;
    // The whole identity matched once the serial number was confirmed and the scan wraps.
    if (sub == 3 && next == 0) state_ = LssState::kConfiguration;
  }
  return true;
}

}  // namespace sh::canopen
