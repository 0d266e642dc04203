// The declared dictionary and its runtime form: structure of the table, bus access checks with
// their CiA 301 abort codes, node-id relative entries, the write handler, and the PDO mappings
// pointing at entries that exist, are mappable and have the mapped width.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <string>

#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/od_table.hpp"
#include "firmware/canopen/pdo.hpp"

namespace sh::canopen {
namespace {

// A fresh dictionary per test (30 KiB, so on the heap).
class CanopenOd : public ::testing::Test {
 protected:
  std::unique_ptr<ObjectDictionary> od_ = std::make_unique<ObjectDictionary>();
};

TEST_F(CanopenOd, EntriesAreSortedUniqueAndCountedAtCompileTime) {
  ObjectDictionary& od = *od_;
  ASSERT_EQ(od.size(), kOdEntryCount);
  for (size_t i = 1; i < od.size(); ++i) {
    const OdEntry& a = od.entry(i - 1);
    const OdEntry& b = od.entry(i);
    EXPECT_TRUE(a.index < b.index || (a.index == b.index && a.sub < b.sub))
        << std::hex << a.index << "sub" << +a.sub << " before " << b.index << "sub" << +b.sub;
  }
}

TEST_F(CanopenOd, EveryObjectHasSubIndexZeroHoldingItsHighestSubIndex) {
  ObjectDictionary& od = *od_;
  for (size_t i = 0; i < od.size(); ++i) {
    const OdEntry& e = od.entry(i);
    if (e.sub != 0 || e.object->code == ObjectCode::kVar) continue;
    uint8_t highest = 0;
    for (size_t k = i + 1; k < od.size() && od.entry(k).index == e.index; ++k) {
      highest = od.entry(k).sub;
    }
    if (e.index == kIdxErrorHistory) continue;  // sub 0 counts the errors
    EXPECT_EQ(e.value, highest) << std::hex << e.index;
  }
}

TEST_F(CanopenOd, MandatoryObjectsOfCia301ArePresentWithTheirTypes) {
  ObjectDictionary& od = *od_;
  const OdEntry* e = nullptr;
  ASSERT_EQ(od.Lookup(0x1000, 0, &e), SdoAbort::kNone);
  EXPECT_EQ(e->type(), DataType::kUnsigned32);
  ASSERT_EQ(od.Lookup(0x1001, 0, &e), SdoAbort::kNone);
  EXPECT_EQ(e->type(), DataType::kUnsigned8);
  ASSERT_EQ(od.Lookup(0x1017, 0, &e), SdoAbort::kNone);
  EXPECT_EQ(e->type(), DataType::kUnsigned16);
  EXPECT_EQ(e->access(), Access::kRw);
  for (uint8_t sub = 1; sub <= 4; ++sub) {
    ASSERT_EQ(od.Lookup(0x1018, sub, &e), SdoAbort::kNone);
    EXPECT_EQ(e->type(), DataType::kUnsigned32);
  }
  EXPECT_EQ(od.Get(0x1018, 0), 4u);
  EXPECT_EQ(od.Get(0x1018, 2), kProductCode);
  EXPECT_STREQ(od.GetString(0x1008, 0), kDeviceName);
}

TEST_F(CanopenOd, CobIdsFollowTheNodeIdAfterResetCommunication) {
  ObjectDictionary& od = *od_;
  EXPECT_EQ(od.Get(kIdxEmcyCobId, 0), 0x81u);
  od.ResetCommunication(42);
  EXPECT_EQ(od.Get(kIdxEmcyCobId, 0), 0x80u + 42);
  EXPECT_EQ(od.Get(kIdxSdoServer, 1), 0x600u + 42);
  EXPECT_EQ(od.Get(kIdxSdoServer, 2), 0x580u + 42);
  EXPECT_EQ(TpdoCobId(od, kTpdoHeader), 0x180u + 42);
  EXPECT_EQ(TpdoCobId(od, kTpdoAnswerFirst), kCobIdInvalid | (0x1C0u + 42));
  EXPECT_EQ(RpdoCobId(od, kRpdoRequest), 0x300u + 42);
}

TEST_F(CanopenOd, ResetCommunicationRestoresWrittenCommunicationValuesOnly) {
  ObjectDictionary& od = *od_;
  const uint8_t hb[2] = {0xF4, 0x01};  // 500 ms
  ASSERT_EQ(od.Write(kIdxHeartbeatTime, 0, hb, 2), SdoAbort::kNone);
  const uint8_t budget[2] = {0x2C, 0x01};  // 300 ms
  ASSERT_EQ(od.Write(kIdxSettings, kSubBudget, budget, 2), SdoAbort::kNone);
  od.Set(kIdxErrorRegister, 0, 0x11);
  od.ResetCommunication(1);
  EXPECT_EQ(od.Get(kIdxHeartbeatTime, 0), 200u);
  EXPECT_EQ(od.Get(kIdxSettings, kSubBudget), 300u);  // application area keeps its value
  EXPECT_EQ(od.Get(kIdxErrorRegister, 0), 0x11u);     // live value, not a parameter
}

TEST_F(CanopenOd, BusAccessIsCheckedWithTheCiaAbortCodes) {
  ObjectDictionary& od = *od_;
  uint8_t buf[64];
  size_t n = 0;
  EXPECT_EQ(od.Read(0x1234, 0, buf, sizeof(buf), &n), SdoAbort::kNoObject);
  EXPECT_EQ(od.Read(0x1018, 9, buf, sizeof(buf), &n), SdoAbort::kNoSubIndex);
  const uint8_t four[4] = {1, 2, 3, 4};
  EXPECT_EQ(od.Write(0x1000, 0, four, 4), SdoAbort::kReadOnly);
  EXPECT_EQ(od.Write(0x1018, 1, four, 4), SdoAbort::kReadOnly);
  // A PDO's transmission type is read-only, but the value it holds may be written back (a
  // configurator writes what the EDS says); another value, or another width, is refused.
  const uint8_t event_driven[1] = {0xFE}, cyclic[1] = {0x01};
  EXPECT_EQ(od.Write(0x1800, 2, event_driven, 1), SdoAbort::kNone);
  EXPECT_EQ(od.Write(0x1400, 2, event_driven, 1), SdoAbort::kNone);
  EXPECT_EQ(od.Write(0x1800, 2, cyclic, 1), SdoAbort::kReadOnly);
  EXPECT_EQ(od.Write(0x1800, 2, four, 2), SdoAbort::kReadOnly);
  EXPECT_EQ(od.Get(0x1800, 2), 0xFEu);
  EXPECT_EQ(od.Write(kIdxHeartbeatTime, 0, four, 4), SdoAbort::kLengthTooHigh);
  EXPECT_EQ(od.Write(kIdxHeartbeatTime, 0, four, 1), SdoAbort::kLengthTooLow);
  const uint8_t too_high[2] = {0x11, 0x27};  // 10001 ms
  EXPECT_EQ(od.Write(kIdxHeartbeatTime, 0, too_high, 2), SdoAbort::kValueTooHigh);
  const uint8_t too_low[2] = {19, 0};  // budget 19 ms
  EXPECT_EQ(od.Write(kIdxSettings, kSubBudget, too_low, 2), SdoAbort::kValueTooLow);
  EXPECT_EQ(od.Get(kIdxSettings, kSubBudget), 1000u);  // refused writes store nothing
  ASSERT_EQ(od.Read(0x1008, 0, buf, sizeof(buf), &n), SdoAbort::kNone);
  EXPECT_EQ(std::string(reinterpret_cast<char*>(buf), n), kDeviceName);
  EXPECT_EQ(od.Read(0x1008, 0, buf, 3, &n), SdoAbort::kLengthTooHigh);
}

TEST_F(CanopenOd, SignedValuesRoundTripInTheirWidth) {
  ObjectDictionary& od = *od_;
  ASSERT_TRUE(od.Set(kIdxResultObject + 3, kSubObjX, -17934));
  ASSERT_TRUE(od.Set(kIdxResultObject + 3, kSubObjQw, -16384));
  EXPECT_EQ(od.GetSigned(kIdxResultObject + 3, kSubObjX), -17934);
  EXPECT_EQ(od.GetSigned(kIdxResultObject + 3, kSubObjQw), -16384);
  EXPECT_EQ(od.Get(kIdxResultObject + 3, kSubObjQw), 0xC000u);
  uint8_t buf[8];
  size_t n = 0;
  ASSERT_EQ(od.Read(kIdxResultObject + 3, kSubObjX, buf, sizeof(buf), &n), SdoAbort::kNone);
  ASSERT_EQ(n, 4u);
  EXPECT_EQ(buf[0] | buf[1] << 8 | buf[2] << 16 | buf[3] << 24, -17934);
}

class Veto final : public WriteHandler {
 public:
  SdoAbort OnWrite(const OdEntry& entry, uint32_t value) override {
    last_index = entry.index;
    last_value = value;
    return value == 7 ? SdoAbort::kInvalidValue : SdoAbort::kNone;
  }
  uint16_t last_index = 0;
  uint32_t last_value = 0;
};

TEST_F(CanopenOd, TheWriteHandlerSeesAcceptedValuesAndMayRefuseThem) {
  ObjectDictionary& od = *od_;
  Veto veto;
  od.set_write_handler(&veto);
  const uint8_t seven[4] = {7, 0, 0, 0};
  const uint8_t five[4] = {5, 0, 0, 0};
  EXPECT_EQ(od.Write(kIdxSettings, kSubModelMask, seven, 4), SdoAbort::kInvalidValue);
  EXPECT_EQ(od.Get(kIdxSettings, kSubModelMask), 0xFFFFFFFFu);
  EXPECT_EQ(od.Write(kIdxSettings, kSubModelMask, five, 4), SdoAbort::kNone);
  EXPECT_EQ(od.Get(kIdxSettings, kSubModelMask), 5u);
  EXPECT_EQ(veto.last_index, kIdxSettings);
  // Refused before the handler: it never sees out-of-range values.
  veto.last_index = 0;
  const uint8_t bad_mode[1] = {3};
  EXPECT_EQ(od.Write(kIdxSettings, kSubResultMode, bad_mode, 1), SdoAbort::kValueTooHigh);
  EXPECT_EQ(veto.last_index, 0);
  od.set_write_handler(nullptr);
}

TEST_F(CanopenOd, PdoMappingsNameMappableEntriesOfTheMappedWidth) {
  ObjectDictionary& od = *od_;
  const auto check = [&](uint16_t map_index, bool transmit) {
    const uint8_t count = static_cast<uint8_t>(od.Get(map_index, 0));
    ASSERT_GT(count, 0u) << std::hex << map_index;
    size_t bits = 0;
    for (uint8_t k = 1; k <= count; ++k) {
      const uint32_t m = od.Get(map_index, k);
      const OdEntry* e = od.Find(static_cast<uint16_t>(m >> 16), static_cast<uint8_t>(m >> 8));
      ASSERT_NE(e, nullptr) << std::hex << map_index << " maps " << m;
      EXPECT_TRUE(e->row->pdo) << std::hex << m << " is not mappable";
      EXPECT_EQ(DataTypeSize(e->type()) * 8, m & 0xFF) << std::hex << m;
      if (transmit) {
        EXPECT_TRUE(Readable(e->access())) << std::hex << m;
      } else {
        EXPECT_TRUE(Writable(e->access())) << std::hex << m;
      }
      bits += m & 0xFF;
    }
    EXPECT_LE(bits, 64u) << std::hex << map_index;
  };
  for (int n = 0; n < kTpdoCount; ++n) check(static_cast<uint16_t>(kIdxTpdoMap + n), true);
  for (int n = 0; n < kRpdoCount; ++n) check(static_cast<uint16_t>(kIdxRpdoMap + n), false);
}

TEST_F(CanopenOd, ManufacturerObjectsCoverSettingsAndEveryResultObject) {
  ObjectDictionary& od = *od_;
  for (uint16_t i = 0; i < protocol::kMaxResultObjects; ++i) {
    EXPECT_NE(od.Find(static_cast<uint16_t>(kIdxResultObject + i), kSubObjQz), nullptr) << i;
  }
  EXPECT_EQ(od.Find(static_cast<uint16_t>(kIdxResultObject + protocol::kMaxResultObjects), 0),
            nullptr);
  EXPECT_EQ(od.Get(kIdxSettings, kSubBudget), 1000u);
  EXPECT_NE(od.Find(kIdxModelNames, kMaxModelNames), nullptr);
}

}  // namespace
}  // namespace sh::canopen
