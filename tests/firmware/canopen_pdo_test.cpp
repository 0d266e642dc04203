// PDOs packed from the dictionary's mappings against the stream encoders (the same bytes by two
// routes), the PDO-mode answers, RPDO unpacking, result modes and COB-ID writes; the error
// register and EMCY sequence of ErrorState.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "firmware/canopen/error_state.hpp"
#include "firmware/canopen/object_dictionary.hpp"
#include "firmware/canopen/pdo.hpp"
#include "firmware/canopen/result_objects.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"

namespace sh::canopen {
namespace {

constexpr uint8_t kPdoNode = 7;

protocol::ResultSet TwoObjects() {
  protocol::ResultSet set;
  set.sequence = 0x1234;
  set.request_id = 77;
  set.status = protocol::ResultStatus::kTimeBudgetHit;
  set.processing_time_us = 92'049;
  set.output_frame = static_cast<uint8_t>(OutputFrame::kRobotBase);
  set.object_count = 2;
  set.objects[0].model_id = 3;
  set.objects[0].instance = 0;
  set.objects[0].score = 0.7163;
  set.objects[0].cam_t_model_mm[0] = -179.34;
  set.objects[0].cam_t_model_mm[1] = 12.5;
  set.objects[0].cam_t_model_mm[2] = 1393.251;
  const double q[4] = {-0.5, 0.5, -0.5, 0.5};  // w < 0: sent negated
  for (int k = 0; k < 4; ++k) set.objects[0].cam_q_model[k] = q[k];
  set.objects[1].model_id = 3;
  set.objects[1].instance = 1;
  set.objects[1].score = 0.5;
  set.objects[1].cam_t_model_mm[2] = 800;
  return set;
}

class CanopenPdo : public ::testing::Test {
 protected:
  CanopenPdo() { od_->ResetCommunication(kPdoNode); }
  hal::CanFrame Pack(int n) {
    hal::CanFrame f;
    const Status s = PackTpdo(*od_, n, &f);
    EXPECT_TRUE(s.ok()) << s.message();
    return f;
  }
  static void ExpectSameFrame(const hal::CanFrame& a, const hal::CanFrame& b) {
    EXPECT_EQ(a.id, b.id);
    ASSERT_EQ(a.len, b.len);
    for (int i = 0; i < a.len; ++i) EXPECT_EQ(a.data[i], b.data[i]) << "byte " << i;
  }

  std::unique_ptr<ObjectDictionary> od_ = std::make_unique<ObjectDictionary>();
  ResultObjects results_{od_.get()};
};

TEST_F(CanopenPdo, HeaderAndEndTpdosEqualTheStreamEncoding) {
  const protocol::ResultSet set = TwoObjects();
  Vector<hal::CanFrame, protocol::kMaxResultFrames> frames;
  ASSERT_TRUE(protocol::EncodeResultSet(set, kPdoNode, frames).ok());
  const hal::CanFrame& end = frames[frames.size() - 1];
  ASSERT_TRUE(results_.Store(set, end.data[3]).ok());
  ExpectSameFrame(Pack(kTpdoHeader), frames[0]);
  ExpectSameFrame(Pack(kTpdoStreamEnd), end);
  EXPECT_EQ(end.len, protocol::kResultEndLength);
  EXPECT_EQ(end.data[4], static_cast<uint8_t>(OutputFrame::kRobotBase));
  // The stream object frame's mapping describes its 8 bytes.
  EXPECT_EQ(TpdoLength(*od_, kTpdoStreamObject), 8u);
  EXPECT_EQ(TpdoCobId(*od_, kTpdoStreamObject), frames[1].id);
}

TEST_F(CanopenPdo, AckTpdoEqualsTheCommandAckEncoding) {
  protocol::CommandAck ack;
  ack.command_code = 0x01;
  ack.status = 8;
  ack.request_id = 0xBEEF;
  ack.value = 0x01020304;
  StoreCommandAck(od_.get(), ack);
  const Result<hal::CanFrame> expected = protocol::EncodeCommandAck(ack, kPdoNode);
  ASSERT_TRUE(expected.ok());
  ExpectSameFrame(Pack(kTpdoAck), *expected);
}

TEST_F(CanopenPdo, AnswersCarryTheStreamsRawPoseOfTheRequestedObject) {
  const protocol::ResultSet set = TwoObjects();
  ASSERT_TRUE(results_.Store(set, 0x5A).ok());
  EXPECT_EQ(results_.Answer(9, 0), AnswerStatus::kOk);
  protocol::EncodedPose e{};
  ASSERT_TRUE(protocol::EncodePose(set.objects[0], 0, &e).ok());
  const hal::CanFrame a = Pack(kTpdoAnswerFirst);
  const hal::CanFrame xy = Pack(kTpdoAnswerFirst + 1);
  const hal::CanFrame zq = Pack(kTpdoAnswerFirst + 2);
  const hal::CanFrame qq = Pack(kTpdoAnswerFirst + 3);
  EXPECT_EQ(a.id, 0x1C0u + kPdoNode);
  EXPECT_EQ(xy.id, 0x2C0u + kPdoNode);
  EXPECT_EQ(zq.id, 0x3C0u + kPdoNode);
  EXPECT_EQ(qq.id, 0x4C0u + kPdoNode);
  ASSERT_EQ(a.len, 8);
  EXPECT_EQ(a.data[0], 9);     // counter
  EXPECT_EQ(a.data[1], 0);     // object index
  EXPECT_EQ(a.data[2], 0);     // status ok
  EXPECT_EQ(a.data[3], 3);     // model
  EXPECT_EQ(a.data[4], 0);     // instance
  EXPECT_EQ(a.data[5], 0x34);  // sequence low byte
  EXPECT_EQ(a.data[6] | a.data[7] << 8, e.score_raw);
  const auto i32 = [](const uint8_t* p) {
    return static_cast<int32_t>(static_cast<uint32_t>(p[0]) | p[1] << 8 | p[2] << 16 |
                                static_cast<uint32_t>(p[3]) << 24);
  };
  const auto i16 = [](const uint8_t* p) { return static_cast<int16_t>(p[0] | p[1] << 8); };
  ASSERT_EQ(xy.len, 8);
  EXPECT_EQ(i32(&xy.data[0]), -17934);
  EXPECT_EQ(i32(&xy.data[4]), 1250);
  ASSERT_EQ(zq.len, 8);
  EXPECT_EQ(i32(&zq.data[0]), 139325);
  EXPECT_EQ(i16(&zq.data[4]), e.q_raw[0]);
  EXPECT_EQ(e.q_raw[0], 8192);  // w >= 0 on the bus
  EXPECT_EQ(i16(&zq.data[6]), e.q_raw[1]);
  ASSERT_EQ(qq.len, 7);
  EXPECT_EQ(i16(&qq.data[0]), e.q_raw[2]);
  EXPECT_EQ(i16(&qq.data[2]), e.q_raw[3]);
  EXPECT_EQ(qq.data[4], 2);  // object count of the set
  EXPECT_EQ(qq.data[5], static_cast<uint8_t>(OutputFrame::kRobotBase));
  EXPECT_EQ(qq.data[6], 9);  // counter again: first and last frame agree

  EXPECT_EQ(results_.Answer(10, 1), AnswerStatus::kOk);
  EXPECT_EQ(Pack(kTpdoAnswerFirst).data[4], 1);  // instance 1
  EXPECT_EQ(results_.Answer(11, 2), AnswerStatus::kNoObject);
  const hal::CanFrame none = Pack(kTpdoAnswerFirst);
  EXPECT_EQ(none.data[2], 1);
  EXPECT_EQ(none.data[3], 0);
  EXPECT_EQ(Pack(kTpdoAnswerFirst + 1).data[0], 0);
}

TEST_F(CanopenPdo, AnswerBeforeAnySetSaysSo) {
  EXPECT_EQ(results_.Answer(1, 0), AnswerStatus::kNoSet);
  EXPECT_EQ(Pack(kTpdoAnswerFirst).data[2], 2);
}

TEST_F(CanopenPdo, ResultSetIsReadableFromTheObjectRecords) {
  const protocol::ResultSet set = TwoObjects();
  ASSERT_TRUE(results_.Store(set, 0x5A).ok());
  EXPECT_EQ(od_->Get(kIdxResultSet, kSubSetCount), 2u);
  EXPECT_EQ(od_->Get(kIdxResultSet, kSubSetTime), 920u);
  EXPECT_EQ(od_->GetSigned(kIdxResultObject, kSubObjZ), 139325);
  EXPECT_EQ(od_->Get(kIdxResultObject + 1, kSubObjInstance), 1u);
  // A shorter set clears the records it no longer uses.
  protocol::ResultSet one = set;
  one.object_count = 1;
  ASSERT_TRUE(results_.Store(one, 0).ok());
  EXPECT_EQ(od_->GetSigned(kIdxResultObject + 1, kSubObjZ), 0);
  // A pose outside the range stores nothing.
  protocol::ResultSet bad = set;
  bad.objects[1].score = 1.5;
  EXPECT_FALSE(results_.Store(bad, 0).ok());
  EXPECT_EQ(od_->Get(kIdxResultSet, kSubSetCount), 1u);
}

TEST_F(CanopenPdo, RequestRpdoIsUnpackedIntoTheDictionary) {
  hal::CanFrame f;
  f.id = 0x300 + kPdoNode;
  f.len = 2;
  f.data[0] = 42;
  f.data[1] = 5;
  ASSERT_EQ(RpdoFor(*od_, f), kRpdoRequest);
  EXPECT_EQ(UnpackRpdo(od_.get(), kRpdoRequest, f), SdoAbort::kNone);
  EXPECT_EQ(od_->Get(kIdxObjectRequest, kSubRequestCounter), 42u);
  EXPECT_EQ(od_->Get(kIdxObjectRequest, kSubRequestIndex), 5u);
  f.len = 1;
  EXPECT_EQ(UnpackRpdo(od_.get(), kRpdoRequest, f), SdoAbort::kLengthTooLow);
  f.id = 0x200 + kPdoNode;
  EXPECT_EQ(RpdoFor(*od_, f), kRpdoCommand);
  f.id = 0x300 + kPdoNode + 1;
  EXPECT_EQ(RpdoFor(*od_, f), -1);
  // An invalid RPDO listens to nothing.
  od_->Set(kIdxRpdoComm + kRpdoRequest, 1, kCobIdInvalid | (0x300 + kPdoNode));
  f.id = 0x300 + kPdoNode;
  EXPECT_EQ(RpdoFor(*od_, f), -1);
}

TEST_F(CanopenPdo, ResultModeSwitchesTheValidBits) {
  EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoStreamObject)));
  EXPECT_FALSE(CobIdValid(TpdoCobId(*od_, kTpdoAnswerFirst)));
  ApplyResultMode(od_.get(), ResultMode::kPdo);
  EXPECT_FALSE(CobIdValid(TpdoCobId(*od_, kTpdoStreamObject)));
  EXPECT_FALSE(CobIdValid(TpdoCobId(*od_, kTpdoStreamEnd)));
  for (int k = 0; k < kTpdoAnswerCount; ++k) {
    EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoAnswerFirst + k)));
  }
  EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoHeader)));
  EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoAck)));
  ApplyResultMode(od_.get(), ResultMode::kBoth);
  EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoStreamObject)));
  EXPECT_TRUE(CobIdValid(TpdoCobId(*od_, kTpdoAnswerFirst + 3)));
  EXPECT_EQ(CanIdOf(TpdoCobId(*od_, kTpdoAnswerFirst + 3)), 0x4C0u + kPdoNode);
}

TEST_F(CanopenPdo, CobIdWritesFollowCia301) {
  const auto check = [&](int tpdo, uint32_t value) {
    const OdEntry* e = od_->Find(static_cast<uint16_t>(kIdxTpdoComm + tpdo), 1);
    EXPECT_TRUE(IsPdoCobIdEntry(*e));
    return CheckCobIdWrite(*e, value);
  };
  // Switching off and on is always allowed.
  EXPECT_EQ(check(kTpdoHeader, kCobIdInvalid | (0x180 + kPdoNode)), SdoAbort::kNone);
  // The fixed PDOs keep their identifier.
  EXPECT_EQ(check(kTpdoHeader, 0x190), SdoAbort::kInvalidValue);
  // An answer PDO moves while invalid, not while valid, never to a reserved id or extended.
  EXPECT_EQ(check(kTpdoAnswerFirst, kCobIdInvalid | 0x250), SdoAbort::kNone);
  EXPECT_EQ(check(kTpdoAnswerFirst, kCobIdInvalid | 0x601), SdoAbort::kInvalidValue);
  EXPECT_EQ(check(kTpdoAnswerFirst, kCobIdInvalid | kCobIdExtended | 0x250),
            SdoAbort::kInvalidValue);
  ApplyResultMode(od_.get(), ResultMode::kPdo);
  EXPECT_EQ(check(kTpdoAnswerFirst, 0x250), SdoAbort::kInvalidValue);
}

// ---------------------------------------------------------------------------------------------

class CanopenErrors : public ::testing::Test {
 protected:
  std::unique_ptr<ObjectDictionary> od_ = std::make_unique<ObjectDictionary>();
  ErrorState errors_{od_.get()};
};

TEST_F(CanopenErrors, RegisterFollowsTheActiveConditionsAndClearsWithAnErrorReset) {
  const EmcyMessage camera = errors_.Raise(1u << 2, 0x7300, 0x03000000);
  EXPECT_EQ(camera.code, 0x7300);
  EXPECT_EQ(camera.error_register, 0x81);  // generic + manufacturer
  EXPECT_EQ(od_->Get(kIdxErrorRegister, 0), 0x81u);
  const EmcyMessage bus = errors_.Raise(1u << 4, 0x8100, 3);
  EXPECT_EQ(bus.error_register, 0x91);  // + communication
  EmcyMessage reset;
  ASSERT_TRUE(errors_.Clear(1u << 2, &reset));
  EXPECT_EQ(reset.code, 0);
  EXPECT_EQ(reset.error_register, 0x11);         // the CAN condition remains
  EXPECT_FALSE(errors_.Clear(1u << 2, &reset));  // nothing to clear twice
  ASSERT_TRUE(errors_.ClearAll(0xFFFFFFFF, &reset));
  EXPECT_EQ(reset.error_register, 0);
  EXPECT_EQ(od_->Get(kIdxErrorRegister, 0), 0u);
}

TEST_F(CanopenErrors, EventsAreFollowedByTheirErrorReset) {
  EmcyMessage error, reset;
  errors_.Event(0x8200, 0x03020005, &error, &reset);
  EXPECT_EQ(error.code, 0x8200);
  EXPECT_EQ(error.error_register, 0x11);
  EXPECT_EQ(reset.code, 0);
  EXPECT_EQ(reset.error_register, 0);
  EXPECT_EQ(od_->Get(kIdxErrorRegister, 0), 0u);
  // With a fault active the reset keeps its bits.
  (void)errors_.Raise(1u << 0, 0x6300, 1);
  errors_.Event(0x8200, 0x03020005, &error, &reset);
  EXPECT_EQ(error.error_register, 0x91);
  EXPECT_EQ(reset.error_register, 0x81);
}

TEST_F(CanopenErrors, HistoryKeepsTheNewestFirstAndClearsOnWritingZero) {
  for (uint32_t i = 0; i < 10; ++i) (void)errors_.Raise(1u << 0, 0x6300, i);
  EXPECT_EQ(od_->Get(kIdxErrorHistory, 0), kErrorHistoryDepth);
  EXPECT_EQ(od_->Get(kIdxErrorHistory, 1), 9u << 16 | 0x6300);
  EXPECT_EQ(od_->Get(kIdxErrorHistory, kErrorHistoryDepth), 2u << 16 | 0x6300);
  EXPECT_EQ(errors_.WriteHistoryCount(3), SdoAbort::kInvalidValue);
  EXPECT_EQ(errors_.WriteHistoryCount(0), SdoAbort::kNone);
  EXPECT_EQ(od_->Get(kIdxErrorHistory, 1), 0u);
}

}  // namespace
}  // namespace sh::canopen
