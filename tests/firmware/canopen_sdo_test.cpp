// SDO server against hand-built client frames (CiA 301 7.2.4.3): expedited and segmented
// upload and download, the abort codes, toggle and timeout handling, and a small client that
// reads and writes through the server the way a manager does.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/sdo_server.hpp"

namespace sh::canopen {
namespace {

constexpr uint8_t kSdoNode = 5;

hal::CanFrame Request(std::initializer_list<uint8_t> bytes) {
  hal::CanFrame f;
  f.id = 0x600 + kSdoNode;
  f.len = 8;
  size_t i = 0;
  for (uint8_t b : bytes) f.data[i++] = b;
  return f;
}

uint32_t AbortCode(const hal::CanFrame& f) {
  return static_cast<uint32_t>(f.data[4]) | f.data[5] << 8 | f.data[6] << 16 |
         static_cast<uint32_t>(f.data[7]) << 24;
}

class CanopenSdo : public ::testing::Test {
 protected:
  CanopenSdo() { od_->ResetCommunication(kSdoNode); }

  hal::CanFrame Exchange(const hal::CanFrame& request, int64_t now_ns = 0) {
    hal::CanFrame response;
    EXPECT_TRUE(server_.Handle(request, now_ns, &response));
    EXPECT_EQ(response.id, 0x580u + kSdoNode);
    EXPECT_EQ(response.len, 8);
    return response;
  }

  // A client upload: expedited or segmented, as the server chooses. Returns the abort code or 0.
  uint32_t Upload(uint16_t index, uint8_t sub, std::vector<uint8_t>* data) {
    hal::CanFrame r = Exchange(
        Request({0x40, static_cast<uint8_t>(index), static_cast<uint8_t>(index >> 8), sub}));
    if (r.data[0] == 0x80) return AbortCode(r);
    EXPECT_EQ(r.data[0] & 0xE0, 0x40);
    data->clear();
    if (r.data[0] & 0x02) {
      const size_t n = (r.data[0] & 0x01) ? 4 - ((r.data[0] >> 2) & 3) : 4;
      data->assign(r.data + 4, r.data + 4 + n);
      return 0;
    }
    const size_t size = r.data[4] | r.data[5] << 8;
    uint8_t toggle = 0;
    while (true) {
      r = Exchange(Request({static_cast<uint8_t>(0x60 | toggle << 4)}));
      if (r.data[0] == 0x80) return AbortCode(r);
      EXPECT_EQ((r.data[0] >> 4) & 1, toggle);
      const size_t n = 7 - ((r.data[0] >> 1) & 7);
      data->insert(data->end(), r.data + 1, r.data + 1 + n);
      toggle ^= 1;
      if (r.data[0] & 1) break;
    }
    EXPECT_EQ(data->size(), size);
    return 0;
  }

  std::unique_ptr<ObjectDictionary> od_ = std::make_unique<ObjectDictionary>();
  SdoServer server_{od_.get()};
};

TEST_F(CanopenSdo, ExpeditedUploadsCarryTheExactSize) {
  hal::CanFrame r = Exchange(Request({0x40, 0x00, 0x10, 0x00}));  // 0x1000 device type
  EXPECT_EQ(r.data[0], 0x43);                                     // e, s, 4 bytes
  EXPECT_EQ(r.data[1], 0x00);
  EXPECT_EQ(r.data[2], 0x10);
  r = Exchange(Request({0x40, 0x17, 0x10, 0x00}));  // 0x1017 heartbeat, U16
  EXPECT_EQ(r.data[0], 0x4B);
  EXPECT_EQ(r.data[4] | r.data[5] << 8, 200);
  r = Exchange(Request({0x40, 0x01, 0x10, 0x00}));  // 0x1001, U8
  EXPECT_EQ(r.data[0], 0x4F);
  r = Exchange(Request({0x40, 0x18, 0x10, 0x02}));  // 0x1018 sub 2 product code
  EXPECT_EQ(r.data[0], 0x43);
  EXPECT_EQ(r.data[4] | r.data[5] << 8 | r.data[6] << 16 | static_cast<uint32_t>(r.data[7]) << 24,
            kProductCode);
  r = Exchange(Request({0x40, 0x14, 0x10, 0x00}));  // COB-ID EMCY follows the node id
  EXPECT_EQ(r.data[4], 0x80 + kSdoNode);
}

TEST_F(CanopenSdo, SegmentedUploadOfTheDeviceNameAlternatesTheToggle) {
  od_->SetString(kIdxHardwareVersion, 0, "aarch64 board rev B, 2 cameras");
  std::vector<uint8_t> data;
  ASSERT_EQ(Upload(kIdxHardwareVersion, 0, &data), 0u);
  EXPECT_EQ(std::string(data.begin(), data.end()), "aarch64 board rev B, 2 cameras");
  ASSERT_EQ(Upload(kIdxDeviceName, 0, &data), 0u);
  EXPECT_EQ(std::string(data.begin(), data.end()), kDeviceName);
  EXPECT_FALSE(server_.busy());
}

TEST_F(CanopenSdo, WrongToggleAbortsTheTransfer) {
  od_->SetString(kIdxHardwareVersion, 0, "0123456789abcdef");
  hal::CanFrame r = Exchange(Request({0x40, 0x09, 0x10, 0x00}));
  EXPECT_EQ(r.data[0], 0x41);
  r = Exchange(Request({0x60}));
  EXPECT_EQ(r.data[0], 0x00);     // toggle 0, 7 bytes, more to come
  r = Exchange(Request({0x60}));  // toggle should now be 1
  EXPECT_EQ(r.data[0], 0x80);
  EXPECT_EQ(AbortCode(r), 0x05030000u);
  EXPECT_FALSE(server_.busy());
}

TEST_F(CanopenSdo, ExpeditedDownloadWritesAndReadsBack) {
  hal::CanFrame r = Exchange(Request({0x2B, 0x17, 0x10, 0x00, 0xF4, 0x01}));  // 500 ms
  EXPECT_EQ(r.data[0], 0x60);
  EXPECT_EQ(r.data[1], 0x17);
  EXPECT_EQ(od_->Get(kIdxHeartbeatTime, 0), 500u);
  // Size not indicated (e = 1, s = 0): the object's own size is used.
  r = Exchange(Request({0x22, 0x17, 0x10, 0x00, 0x2C, 0x01, 0xAA, 0xBB}));
  EXPECT_EQ(r.data[0], 0x60);
  EXPECT_EQ(od_->Get(kIdxHeartbeatTime, 0), 300u);
}

TEST_F(CanopenSdo, DownloadErrorsAnswerWithTheirAbortCodes) {
  const auto abort_of = [&](std::initializer_list<uint8_t> bytes) {
    const hal::CanFrame r = Exchange(Request(bytes));
    EXPECT_EQ(r.data[0], 0x80);
    return AbortCode(r);
  };
  EXPECT_EQ(abort_of({0x23, 0x00, 0x10, 0x00, 1, 2, 3, 4}), 0x06010002u);  // read-only
  EXPECT_EQ(abort_of({0x23, 0x00, 0x30, 0x00, 1, 2, 3, 4}), 0x06020000u);  // no object
  EXPECT_EQ(abort_of({0x23, 0x18, 0x10, 0x07, 1, 2, 3, 4}), 0x06090011u);  // no sub-index
  EXPECT_EQ(abort_of({0x23, 0x17, 0x10, 0x00, 1, 2, 3, 4}), 0x06070012u);  // 4 bytes into U16
  EXPECT_EQ(abort_of({0x2F, 0x17, 0x10, 0x00, 1}), 0x06070013u);           // 1 byte into U16
  EXPECT_EQ(abort_of({0x2B, 0x17, 0x10, 0x00, 0x11, 0x27}), 0x06090031u);  // 10001 ms
  EXPECT_EQ(abort_of({0x2B, 0x00, 0x20, 0x01, 5, 0}), 0x06090032u);        // budget 5 ms
  EXPECT_EQ(abort_of({0x40, 0x00, 0x30, 0x00}), 0x06020000u);              // upload: no object
  EXPECT_EQ(abort_of({0xC0, 0x17, 0x10, 0x00}), 0x05040001u);              // block download
  EXPECT_EQ(abort_of({0xA0, 0x17, 0x10, 0x00}), 0x05040001u);              // block upload
  EXPECT_EQ(abort_of({0x60}), 0x05040001u);                                // segment, no transfer
  EXPECT_EQ(od_->Get(kIdxHeartbeatTime, 0), 200u);
}

TEST_F(CanopenSdo, SegmentedDownloadIsStoredAfterTheLastSegment) {
  // A client may download 4 bytes segmented: initiate with size 4, one last segment.
  hal::CanFrame r = Exchange(Request({0x21, 0x00, 0x20, 0x02, 4, 0, 0, 0}));  // model mask
  EXPECT_EQ(r.data[0], 0x60);
  EXPECT_TRUE(server_.busy());
  EXPECT_EQ(od_->Get(kIdxSettings, kSubModelMask), 0xFFFFFFFFu);
  r = Exchange(Request({0x07, 0x15, 0, 0, 0}));  // toggle 0, n = 3 (4 bytes), last
  EXPECT_EQ(r.data[0], 0x20);
  EXPECT_EQ(od_->Get(kIdxSettings, kSubModelMask), 0x15u);
  EXPECT_FALSE(server_.busy());
}

TEST_F(CanopenSdo, SegmentedDownloadLongerThanIndicatedIsRefused) {
  hal::CanFrame r = Exchange(Request({0x21, 0x00, 0x20, 0x02, 4, 0, 0, 0}));
  EXPECT_EQ(r.data[0], 0x60);
  r = Exchange(Request({0x01, 1, 2, 3, 4, 5, 6, 7}));  // 7 bytes, last
  EXPECT_EQ(r.data[0], 0x80);
  EXPECT_EQ(AbortCode(r), 0x06070012u);
  EXPECT_EQ(od_->Get(kIdxSettings, kSubModelMask), 0xFFFFFFFFu);
}

TEST_F(CanopenSdo, IdleSegmentedTransferTimesOutWithAnAbort) {
  od_->SetString(kIdxHardwareVersion, 0, "0123456789abcdef");
  (void)Exchange(Request({0x40, 0x09, 0x10, 0x00}), 0);
  hal::CanFrame r;
  EXPECT_FALSE(server_.Poll(kSdoDefaultTimeoutNs - 1, &r));
  ASSERT_TRUE(server_.Poll(kSdoDefaultTimeoutNs, &r));
  EXPECT_EQ(r.data[0], 0x80);
  EXPECT_EQ(r.data[1] | r.data[2] << 8, kIdxHardwareVersion);
  EXPECT_EQ(AbortCode(r), 0x05040000u);
  EXPECT_FALSE(server_.busy());
  EXPECT_EQ(server_.counters().timeouts, 1u);
}

TEST_F(CanopenSdo, ClientAbortEndsTheTransferSilently) {
  od_->SetString(kIdxHardwareVersion, 0, "0123456789abcdef");
  (void)Exchange(Request({0x40, 0x09, 0x10, 0x00}));
  hal::CanFrame r;
  EXPECT_FALSE(server_.Handle(Request({0x80, 0x09, 0x10, 0x00, 0, 0, 4, 5}), 0, &r));
  EXPECT_FALSE(server_.busy());
  EXPECT_EQ(server_.counters().aborts_received, 1u);
}

TEST_F(CanopenSdo, OtherIdentifiersAndShortFramesAreNotTakenForRequests) {
  hal::CanFrame r;
  hal::CanFrame other = Request({0x40, 0x00, 0x10, 0x00});
  other.id = 0x600 + kSdoNode + 1;
  EXPECT_FALSE(server_.Handle(other, 0, &r));
  hal::CanFrame extended = Request({0x40, 0x00, 0x10, 0x00});
  extended.extended = true;
  EXPECT_FALSE(server_.Handle(extended, 0, &r));
  hal::CanFrame shorter = Request({0x40, 0x00, 0x10, 0x00});
  shorter.len = 4;
  ASSERT_TRUE(server_.Handle(shorter, 0, &r));
  EXPECT_EQ(AbortCode(r), 0x05040001u);
}

TEST_F(CanopenSdo, EveryReadableEntryUploadsWithItsTypeSize) {
  for (size_t i = 0; i < od_->size(); ++i) {
    const OdEntry& e = od_->entry(i);
    std::vector<uint8_t> data;
    const uint32_t abort = Upload(e.index, e.sub, &data);
    if (!Readable(e.access())) {
      EXPECT_EQ(abort, 0x06010001u);
      continue;
    }
    ASSERT_EQ(abort, 0u) << std::hex << e.index << "sub" << +e.sub;
    EXPECT_EQ(data.size(), od_->ValueLength(e)) << std::hex << e.index << "sub" << +e.sub;
  }
}

}  // namespace
}  // namespace sh::canopen
