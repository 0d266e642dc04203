// LSS slave (CiA 305): switch state global and selective, configure and store the node id,
// inquire the identity, identify remote slaves by ranges, and the fastscan a master runs to find
// an unconfigured node bit by bit (the algorithm of node-canopen's Lss.fastscan).
#include <gtest/gtest.h>

#include <vector>

#include "firmware/canopen/lss_slave.hpp"

namespace sh::canopen {
namespace {

constexpr LssIdentity kId{0x00000000, 0x53480001, 0x00000001, 0x1234ABCD};

hal::CanFrame Lss(std::initializer_list<uint8_t> bytes) {
  hal::CanFrame f;
  f.id = kLssMasterCobId;
  f.len = 8;
  size_t i = 0;
  for (uint8_t b : bytes) f.data[i++] = b;
  return f;
}

hal::CanFrame LssU32(uint8_t cs, uint32_t v) {
  return Lss({cs, static_cast<uint8_t>(v), static_cast<uint8_t>(v >> 8),
              static_cast<uint8_t>(v >> 16), static_cast<uint8_t>(v >> 24)});
}

uint32_t U32At1(const hal::CanFrame& f) {
  return static_cast<uint32_t>(f.data[1]) | f.data[2] << 8 | f.data[3] << 16 |
         static_cast<uint32_t>(f.data[4]) << 24;
}

class FakeStore final : public LssStore {
 public:
  Status StoreNodeId(uint8_t id) override {
    stored.push_back(id);
    return fail ? Status::Error(StatusCode::kUnavailable, "read-only file system") : Status::Ok();
  }
  std::vector<uint8_t> stored;
  bool fail = false;
};

class CanopenLss : public ::testing::Test {
 protected:
  CanopenLss() { lss_.Init(kId, 5, &store_); }
  LssOutcome Send(const hal::CanFrame& f) { return lss_.Handle(f, &response_); }

  FakeStore store_;
  LssSlave lss_;
  hal::CanFrame response_;
};

TEST_F(CanopenLss, GlobalSwitchConfigureStoreAndInquire) {
  EXPECT_FALSE(Send(Lss({0x11, 9})).respond);  // waiting state: configuration services ignored
  EXPECT_FALSE(Send(Lss({0x04, 1})).respond);
  EXPECT_EQ(lss_.state(), LssState::kConfiguration);
  ASSERT_TRUE(Send(Lss({0x11, 9})).respond);
  EXPECT_EQ(response_.id, kLssSlaveCobId);
  EXPECT_EQ(response_.data[0], 0x11);
  EXPECT_EQ(response_.data[1], 0);
  EXPECT_EQ(lss_.pending_node_id(), 9);
  EXPECT_EQ(lss_.active_node_id(), 5);  // active only after reset communication
  ASSERT_TRUE(Send(Lss({0x11, 0})).respond);
  EXPECT_EQ(response_.data[1], 1);  // 0 is out of range
  ASSERT_TRUE(Send(Lss({0x11, 128})).respond);
  EXPECT_EQ(response_.data[1], 1);
  EXPECT_EQ(lss_.pending_node_id(), 9);
  ASSERT_TRUE(Send(Lss({0x17})).respond);
  EXPECT_EQ(response_.data[0], 0x17);
  EXPECT_EQ(response_.data[1], 0);
  ASSERT_EQ(store_.stored.size(), 1u);
  EXPECT_EQ(store_.stored[0], 9);
  store_.fail = true;
  ASSERT_TRUE(Send(Lss({0x17})).respond);
  EXPECT_EQ(response_.data[1], 2);  // storage media access error
  const uint32_t expected[4] = {kId.vendor_id, kId.product_code, kId.revision, kId.serial};
  for (uint8_t k = 0; k < 4; ++k) {
    ASSERT_TRUE(Send(Lss({static_cast<uint8_t>(0x5A + k)})).respond);
    EXPECT_EQ(response_.data[0], 0x5A + k);
    EXPECT_EQ(U32At1(response_), expected[k]);
  }
  ASSERT_TRUE(Send(Lss({0x5E})).respond);
  EXPECT_EQ(response_.data[1], 5);
  ASSERT_TRUE(Send(Lss({0x13, 0, 4})).respond);
  EXPECT_EQ(response_.data[1], 1);  // bit timing: not supported
  // A configured node leaving configuration keeps its id until reset communication.
  EXPECT_FALSE(Send(Lss({0x04, 0})).apply_pending);
  EXPECT_EQ(lss_.state(), LssState::kWaiting);
}

TEST_F(CanopenLss, SelectiveSwitchNeedsAllFourPartsInOrder) {
  EXPECT_FALSE(Send(LssU32(0x40, kId.vendor_id)).respond);
  EXPECT_FALSE(Send(LssU32(0x41, kId.product_code)).respond);
  EXPECT_FALSE(Send(LssU32(0x42, kId.revision)).respond);
  EXPECT_FALSE(Send(LssU32(0x43, kId.serial + 1)).respond);  // another device
  EXPECT_EQ(lss_.state(), LssState::kWaiting);
  EXPECT_FALSE(Send(LssU32(0x41, kId.product_code)).respond);  // out of order
  EXPECT_FALSE(Send(LssU32(0x43, kId.serial)).respond);
  EXPECT_EQ(lss_.state(), LssState::kWaiting);
  EXPECT_FALSE(Send(LssU32(0x40, kId.vendor_id)).respond);
  EXPECT_FALSE(Send(LssU32(0x41, kId.product_code)).respond);
  EXPECT_FALSE(Send(LssU32(0x42, kId.revision)).respond);
  ASSERT_TRUE(Send(LssU32(0x43, kId.serial)).respond);
  EXPECT_EQ(response_.data[0], 0x44);
  EXPECT_EQ(lss_.state(), LssState::kConfiguration);
}

TEST_F(CanopenLss, IdentifyRemoteSlaveMatchesRanges) {
  const auto identify = [&](uint32_t rev_lo, uint32_t rev_hi, uint32_t ser_lo, uint32_t ser_hi) {
    (void)Send(LssU32(0x46, kId.vendor_id));
    (void)Send(LssU32(0x47, kId.product_code));
    (void)Send(LssU32(0x48, rev_lo));
    (void)Send(LssU32(0x49, rev_hi));
    (void)Send(LssU32(0x4A, ser_lo));
    const LssOutcome out = Send(LssU32(0x4B, ser_hi));
    return out.respond && response_.data[0] == 0x4F;
  };
  EXPECT_TRUE(identify(0, 0xFFFFFFFF, 0, 0xFFFFFFFF));
  EXPECT_TRUE(identify(1, 1, kId.serial, kId.serial));
  EXPECT_FALSE(identify(2, 9, 0, 0xFFFFFFFF));
  EXPECT_FALSE(identify(0, 9, kId.serial + 1, 0xFFFFFFFF));
  // Identify non-configured: this node has an id.
  EXPECT_FALSE(Send(Lss({0x4C})).respond);
}

// The master's side of fastscan, as node-canopen runs it: every bit from 31 down is tested by
// sending it as 0; silence means the bit is 1. Then each part is confirmed (bit_checked 0).
bool FastscanPart(LssSlave* lss, uint8_t sub, uint32_t* found) {
  hal::CanFrame r;
  uint32_t value = 0;
  for (int bit = 31; bit >= 0; --bit) {
    const hal::CanFrame f =
        Lss({0x51, static_cast<uint8_t>(value), static_cast<uint8_t>(value >> 8),
             static_cast<uint8_t>(value >> 16), static_cast<uint8_t>(value >> 24),
             static_cast<uint8_t>(bit), sub, sub});
    if (!lss->Handle(f, &r).respond) value |= 1u << bit;
  }
  const uint8_t next = static_cast<uint8_t>((sub + 1) % 4);
  const hal::CanFrame confirm =
      Lss({0x51, static_cast<uint8_t>(value), static_cast<uint8_t>(value >> 8),
           static_cast<uint8_t>(value >> 16), static_cast<uint8_t>(value >> 24), 0, sub, next});
  *found = value;
  return lss->Handle(confirm, &r).respond && r.data[0] == 0x4F;
}

TEST_F(CanopenLss, FastscanFindsAnUnconfiguredNodeAndItTakesTheNewId) {
  lss_.Init(kId, kNodeIdUnconfigured, &store_);
  ASSERT_TRUE(Send(Lss({0x4C})).respond);  // identify non-configured
  EXPECT_EQ(response_.data[0], 0x50);
  ASSERT_TRUE(Send(Lss({0x51, 0, 0, 0, 0, 0x80, 0, 0})).respond);  // reset: "anyone there?"
  uint32_t parts[4];
  for (uint8_t sub = 0; sub < 4; ++sub) {
    ASSERT_TRUE(FastscanPart(&lss_, sub, &parts[sub])) << +sub;
  }
  EXPECT_EQ(parts[0], kId.vendor_id);
  EXPECT_EQ(parts[1], kId.product_code);
  EXPECT_EQ(parts[2], kId.revision);
  EXPECT_EQ(parts[3], kId.serial);
  EXPECT_EQ(lss_.state(), LssState::kConfiguration);
  ASSERT_TRUE(Send(Lss({0x11, 17})).respond);
  // An unconfigured node takes its new id as soon as the master ends configuration.
  EXPECT_TRUE(Send(Lss({0x04, 0})).apply_pending);
  EXPECT_EQ(lss_.pending_node_id(), 17);
}

TEST_F(CanopenLss, ConfiguredNodesStayOutOfFastscan) {
  EXPECT_FALSE(Send(Lss({0x51, 0, 0, 0, 0, 0x80, 0, 0})).respond);
}

TEST_F(CanopenLss, OtherIdentifiersAreIgnored) {
  hal::CanFrame f = Lss({0x04, 1});
  f.id = 0x7E4;
  EXPECT_FALSE(Send(f).respond);
  EXPECT_EQ(lss_.state(), LssState::kWaiting);
}

}  // namespace
}  // namespace sh::canopen
