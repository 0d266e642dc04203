#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/plc/result_assembler.hpp"
#include "firmware/result_codec.hpp"

namespace sh::protocol {
namespace {

constexpr uint8_t kNode = 5;

// A pose with a random unit quaternion and position, reproducible from the seed.
ObjectPose RandomPose(std::mt19937& rng, uint8_t index) {
  std::uniform_real_distribution<double> pos(-2000.0, 2000.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ObjectPose p;
  p.model_id = static_cast<uint8_t>(index % 32);
  p.instance = static_cast<uint8_t>(index / 32);
  p.score = unit(rng);
  for (double& t : p.cam_t_model_mm) t = pos(rng);
  double n = 0;
  for (double& q : p.cam_q_model) {
    q = gauss(rng);
    n += q * q;
  }
  for (double& q : p.cam_q_model) q /= std::sqrt(n);
  return p;
}

Result<bool> FeedAll(ResultAssembler& assembler, const Vector<CanFrame>& frames) {
  Result<bool> last = false;
  for (const CanFrame& f : frames) {
    last = assembler.Feed(f);
    if (!last.ok()) return last;
  }
  return last;
}

TEST(CanProtocolTest, Crc8MatchesTheCatalogueCheckValue) {
  const char* check = "123456789";
  // CRC-8/SMBUS (poly 0x07, init 0, no reflection) check value from the CRC catalogue.
  EXPECT_EQ(Crc8(reinterpret_cast<const uint8_t*>(check), 9), 0xF4);
}

TEST(CanProtocolTest, ResultSetRoundTripsWithinOneQuantisationStep) {
  std::mt19937 rng(7);
  for (uint8_t count : {0, 1, 3, 64}) {
    ResultSet set;
    set.sequence = static_cast<uint16_t>(0xFFF0 + count);
    set.request_id = 0x1234;
    set.status = ResultStatus::kTimeBudgetHit;
    set.processing_time_us = 123456;
    set.object_count = count;
    for (uint8_t i = 0; i < count; ++i) set.objects[i] = RandomPose(rng, i);

    Vector<CanFrame, kMaxResultFrames> frames;
    const Status s = EncodeResultSet(set, kNode, frames);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_EQ(frames.size(), 2u + 4u * count);
    for (const CanFrame& f : frames) EXPECT_LE(f.len, 8);
    EXPECT_EQ(frames[0].id, 0x180u + kNode);
    EXPECT_EQ(frames[frames.size() - 1].id, 0x380u + kNode);

    ResultAssembler assembler(kNode);
    Result<bool> done = FeedAll(assembler, frames);
    ASSERT_TRUE(done.ok()) << done.status().message();
    ASSERT_TRUE(*done);
    const ResultSet& back = assembler.set();
    EXPECT_EQ(back.sequence, set.sequence);
    EXPECT_EQ(back.request_id, set.request_id);
    EXPECT_EQ(back.status, set.status);
    EXPECT_NEAR(back.processing_time_us, set.processing_time_us, 50);
    ASSERT_EQ(back.object_count, count);
    for (uint8_t i = 0; i < count; ++i) {
      const ObjectPose& a = set.objects[i];
      const ObjectPose& b = back.objects[i];
      EXPECT_EQ(b.model_id, a.model_id);
      EXPECT_EQ(b.instance, a.instance);
      EXPECT_NEAR(b.score, a.score, kScorePerLsb / 2 + 1e-12);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(b.cam_t_model_mm[k], a.cam_t_model_mm[k], kPositionMmPerLsb / 2 + 1e-9);
      }
      // Same rotation: q or -q, each component within half a Q14 step.
      const double sign = a.cam_q_model[0] < 0 ? -1.0 : 1.0;
      EXPECT_GE(b.cam_q_model[0], 0.0);
      for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(b.cam_q_model[k], sign * a.cam_q_model[k], kQuaternionPerLsb / 2 + 1e-12);
      }
    }
  }
}

class CanProtocolSetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(3);
    set_.sequence = 41;
    set_.request_id = 9;
    set_.object_count = 2;
    set_.objects[0] = RandomPose(rng, 0);
    set_.objects[1] = RandomPose(rng, 1);
    ASSERT_TRUE(EncodeResultSet(set_, kNode, frames_).ok());
  }
  ResultSet set_;
  Vector<CanFrame, kMaxResultFrames> frames_;
};

TEST_F(CanProtocolSetTest, CorruptedPayloadFailsTheCrc) {
  frames_[3].data[4] ^= 0x01;
  ResultAssembler assembler(kNode);
  Result<bool> r = FeedAll(assembler, frames_);
  EXPECT_EQ(r.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(std::string(r.status().message()).find("CRC"), std::string::npos);
}

TEST_F(CanProtocolSetTest, MissingFrameIsDetected) {
  ResultAssembler assembler(kNode);
  Status first_error;
  for (size_t i = 0; i < frames_.size(); ++i) {
    if (i == 4) continue;
    Result<bool> r = assembler.Feed(frames_[i]);
    if (!r.ok()) {
      first_error = r.status();
      break;
    }
    EXPECT_FALSE(*r);
  }
  EXPECT_EQ(first_error.code(), StatusCode::kDataLoss);
}

TEST_F(CanProtocolSetTest, ANewHeaderAbandonsAnIncompleteSet) {
  ResultAssembler assembler(kNode);
  ASSERT_TRUE(assembler.Feed(frames_[0]).ok());
  ASSERT_TRUE(assembler.Feed(frames_[1]).ok());
  EXPECT_EQ(assembler.Feed(frames_[0]).status().code(), StatusCode::kDataLoss);
  // The assembler restarted with that header, so the rest of the set completes.
  Result<bool> r = false;
  for (size_t i = 1; i < frames_.size(); ++i) r = assembler.Feed(frames_[i]);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(*r);
}

TEST_F(CanProtocolSetTest, FramesOfOtherNodesAreIgnored) {
  ResultAssembler other(kNode + 1);
  Result<bool> r = FeedAll(other, frames_);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(*r);
}

TEST(CanProtocolTest, ResultEncoderRejectsOutOfRangeValues) {
  Vector<CanFrame, kMaxResultFrames> frames;
  ResultSet set;
  set.object_count = 1;
  set.objects[0].model_id = 32;
  EXPECT_EQ(EncodeResultSet(set, kNode, frames).code(), StatusCode::kOutOfRange);
  set.objects[0].model_id = 1;
  set.objects[0].score = 1.5;
  EXPECT_EQ(EncodeResultSet(set, kNode, frames).code(), StatusCode::kOutOfRange);
  set.objects[0].score = std::nan("");
  EXPECT_EQ(EncodeResultSet(set, kNode, frames).code(), StatusCode::kOutOfRange);
  set.objects[0].score = 0.5;
  set.objects[0].cam_t_model_mm[1] = 3.0e7;  // 30 km
  Status s = EncodeResultSet(set, kNode, frames);
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::string(s.message()).find("position y"), std::string::npos) << s.message();
  set.objects[0].cam_t_model_mm[1] = 0;
  set.objects[0].cam_q_model[0] = 0.5;  // norm 0.5
  EXPECT_EQ(EncodeResultSet(set, kNode, frames).code(), StatusCode::kInvalidArgument);
  set.objects[0].cam_q_model[0] = 1.0;
  EXPECT_EQ(EncodeResultSet(set, 0, frames).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(EncodeResultSet(set, 128, frames).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(frames.size(), 0u);  // nothing appended on error

  Vector<CanFrame, 4> small;
  EXPECT_EQ(EncodeResultSet(set, kNode, small).code(), StatusCode::kResourceExhausted);
  EXPECT_TRUE(EncodeResultSet(set, kNode, frames).ok());
  EXPECT_EQ(frames.size(), 6u);
}

TEST(CanProtocolTest, CommandsRoundTrip) {
  Command commands[5];
  commands[0].code = CommandCode::kTrigger;
  commands[0].request_id = 65535;
  commands[1].code = CommandCode::kSelectModels;
  commands[1].model_mask = 0x80000001u;
  commands[2].code = CommandCode::kSetTimeBudget;
  commands[2].time_budget_ms = kTimeBudgetMaxMs;
  commands[3].code = CommandCode::kClearFault;
  commands[4].code = CommandCode::kSetFreeRunRate;
  commands[4].free_run_rate_dhz = 0;
  for (const Command& c : commands) {
    Result<CanFrame> f = EncodeCommand(c, 127);
    ASSERT_TRUE(f.ok()) << f.status().message();
    EXPECT_EQ(f->id, 0x200u + 127);
    Result<Command> back = DecodeCommand(*f, 127);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(back->code, c.code);
    EXPECT_EQ(back->request_id, c.request_id);
    EXPECT_EQ(back->model_mask, c.model_mask);
    EXPECT_EQ(back->time_budget_ms, c.time_budget_ms);
    EXPECT_EQ(back->free_run_rate_dhz, c.free_run_rate_dhz);
  }
}

CanFrame CommandFrame(std::initializer_list<uint8_t> bytes) {
  CanFrame f;
  f.id = 0x200 + kNode;
  for (uint8_t b : bytes) f.data[f.len++] = b;
  return f;
}

TEST(CanProtocolTest, OutOfRangeCommandsAreRejectedWithAnEmcyDetail) {
  struct Case {
    CanFrame frame;
    StatusCode code = StatusCode::kOk;
    const char* message_part = nullptr;
    uint16_t emcy_code = 0;
  } cases[] = {
      {CommandFrame({0x03, 19, 0}), StatusCode::kOutOfRange, "19 ms", 0x8200},
      {CommandFrame({0x03, 0x11, 0x27}), StatusCode::kOutOfRange, "10001 ms", 0x8200},
      {CommandFrame({0x01, 0, 0}), StatusCode::kOutOfRange, "request id 0", 0x8200},
      {CommandFrame({0x02, 0, 0, 0, 0}), StatusCode::kOutOfRange, "no model", 0x8200},
      {CommandFrame({0x05, 0x2D, 0x01}), StatusCode::kOutOfRange, "30.1 Hz", 0x8200},
      {CommandFrame({0x09}), StatusCode::kInvalidArgument, "unknown command code 0x09", 0x8200},
      {CommandFrame({0x02, 1, 0}), StatusCode::kInvalidArgument, "needs at least 5", 0x8210},
      {CommandFrame({}), StatusCode::kInvalidArgument, "empty", 0x8210},
  };
  for (const Case& c : cases) {
    Result<Command> r = DecodeCommand(c.frame, kNode);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), c.code) << r.status().message();
    EXPECT_NE(std::string(r.status().message()).find(c.message_part), std::string::npos)
        << r.status().message();
    const Emcy e = MakeCommandRejectedEmcy(c.frame, r.status(), FirmwareState::kReady);
    EXPECT_EQ(e.error_code, c.emcy_code) << r.status().message();
    EXPECT_EQ(e.error_register, 0x11);  // generic + communication
    EXPECT_EQ(e.detail >> 24, c.frame.len > 0 ? c.frame.data[0] : 0u);
    EXPECT_EQ((e.detail >> 16) & 0xFF, static_cast<uint32_t>(c.code));
    // The encoder refuses what the decoder refuses.
    if (r.status().code() == StatusCode::kOutOfRange) {
      Command cmd;
      cmd.code = static_cast<CommandCode>(c.frame.data[0]);
      cmd.request_id = cmd.time_budget_ms = cmd.free_run_rate_dhz =
          static_cast<uint16_t>(c.frame.data[1] | c.frame.data[2] << 8);
      cmd.model_mask = 0;
      EXPECT_EQ(EncodeCommand(cmd, kNode).status().code(), StatusCode::kOutOfRange);
    }
  }
  CanFrame wrong_id = CommandFrame({0x04});
  wrong_id.id = 0x201;
  EXPECT_EQ(DecodeCommand(wrong_id, kNode).status().code(), StatusCode::kInvalidArgument);
}

TEST(CanProtocolTest, ModelMaskIsCheckedAgainstLoadedModels) {
  EXPECT_TRUE(CheckModelMask(0x7, 3).ok());
  EXPECT_EQ(CheckModelMask(0x8, 3).code(), StatusCode::kOutOfRange);
  EXPECT_TRUE(CheckModelMask(0x80000000u, 32).ok());
  EXPECT_EQ(CheckModelMask(0, 32).code(), StatusCode::kOutOfRange);
}

TEST(CanProtocolTest, AckEchoesTheCommand) {
  Command c;
  c.code = CommandCode::kTrigger;
  c.request_id = 777;
  Result<CanFrame> cmd = EncodeCommand(c, kNode);
  ASSERT_TRUE(cmd.ok());
  const CommandAck ack = MakeCommandAck(*cmd, Status::Ok());
  Result<CanFrame> f = EncodeCommandAck(ack, kNode);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->id, 0x480u + kNode);
  Result<CommandAck> back = DecodeCommandAck(*f, kNode);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->command_code, 0x01);
  EXPECT_EQ(back->status, 0);
  EXPECT_EQ(back->request_id, 777);
}

TEST(CanProtocolTest, EmcyRoundTrips) {
  Emcy e;
  e.error_code = static_cast<uint16_t>(EmcyCode::kSensor);
  e.error_register = ErrorRegisterFor(e.error_code);
  e.state = FirmwareState::kFault;
  e.detail = 0xDEADBEEF;
  Result<CanFrame> f = EncodeEmcy(e, kNode);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->id, 0x80u + kNode);
  Result<Emcy> back = DecodeEmcy(*f, kNode);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->error_code, 0x7300);
  EXPECT_EQ(back->error_register, 0x81);
  EXPECT_EQ(back->state, FirmwareState::kFault);
  EXPECT_EQ(back->detail, 0xDEADBEEFu);
  EXPECT_EQ(ErrorRegisterFor(0), 0);
}

TEST(CanProtocolTest, BootUpHeartbeatAndNmt) {
  Result<CanFrame> boot = EncodeBootUp(kNode);
  ASSERT_TRUE(boot.ok());
  EXPECT_EQ(boot->id, 0x700u + kNode);
  ASSERT_EQ(boot->len, 1);
  EXPECT_EQ(boot->data[0], 0);
  for (NmtState s : {NmtState::kPreOperational, NmtState::kOperational, NmtState::kStopped}) {
    Result<CanFrame> hb = EncodeHeartbeat(kNode, s);
    ASSERT_TRUE(hb.ok());
    Result<NmtState> back = DecodeHeartbeat(*hb, kNode);
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(*back, s);
  }
  EXPECT_FALSE(EncodeHeartbeat(kNode, NmtState::kBootUp).ok());
  EXPECT_EQ(EncodeBootUp(0).status().code(), StatusCode::kOutOfRange);

  Result<CanFrame> start_all = EncodeNmt(NmtCommand::kStart, 0);
  ASSERT_TRUE(start_all.ok());
  Result<NmtRequest> req = DecodeNmt(*start_all, kNode);
  ASSERT_TRUE(req.ok());
  EXPECT_TRUE(req->addressed);
  EXPECT_EQ(req->command, NmtCommand::kStart);
  Result<CanFrame> stop_other = EncodeNmt(NmtCommand::kStop, kNode + 1);
  req = DecodeNmt(*stop_other, kNode);
  ASSERT_TRUE(req.ok());
  EXPECT_FALSE(req->addressed);
  CanFrame bad = *start_all;
  bad.data[0] = 0x42;
  EXPECT_EQ(DecodeNmt(bad, kNode).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh::protocol

namespace sh::protocol {
namespace {

TEST(CanProtocolTest, PoseFromRigidTransformRotatesLikeTheMatrix) {
  RigidTransform cam_T_model;
  cam_T_model.R = (Eigen::AngleAxisf(2.5f, Eigen::Vector3f(1, -2, 0.5f).normalized()) *
                   Eigen::AngleAxisf(-0.7f, Eigen::Vector3f::UnitZ()))
                      .toRotationMatrix();
  cam_T_model.t_mm = Eigen::Vector3f(12.5f, -300.25f, 950.0f);
  const ObjectPose pose = MakeObjectPose(cam_T_model, 3, 1, 0.75);
  const Eigen::Quaterniond q(pose.cam_q_model[0], pose.cam_q_model[1], pose.cam_q_model[2],
                             pose.cam_q_model[3]);
  const Eigen::Vector3d p_model(40, -5, 17);
  const Eigen::Vector3d by_quaternion =
      q * p_model +
      Eigen::Vector3d(pose.cam_t_model_mm[0], pose.cam_t_model_mm[1], pose.cam_t_model_mm[2]);
  const Eigen::Vector3d by_matrix = (cam_T_model * p_model.cast<float>()).cast<double>();
  EXPECT_LT((by_quaternion - by_matrix).norm(), 1e-3);
  EXPECT_NEAR(q.norm(), 1.0, 1e-9);
  // The encoder accepts it as is.
  ResultSet set;
  set.object_count = 1;
  set.objects[0] = pose;
  Vector<CanFrame, kMaxResultFrames> frames;
  EXPECT_TRUE(EncodeResultSet(set, 1, frames).ok());
}

TEST(CanProtocolTest, PoseQuaternionHasTheSignTheBusSends) {
  // A rotation by more than 180 degrees one way is Eigen's w < 0: reported with w >= 0, as the
  // bus encodes it, so result.json and the frames agree.
  for (float angle : {0.3f, 2.9f, 3.14f, -2.9f}) {
    for (const Eigen::Vector3f& axis :
         {Eigen::Vector3f(1, 2, -3).normalized(), Eigen::Vector3f(-1, 0, 0.2f).normalized()}) {
      RigidTransform cam_T_model;
      cam_T_model.R = Eigen::AngleAxisf(angle, axis).toRotationMatrix();
      const ObjectPose pose = MakeObjectPose(cam_T_model, 0, 0, 1.0);
      EXPECT_GE(pose.cam_q_model[0], 0.0) << angle;
      const Eigen::Quaterniond q(pose.cam_q_model[0], pose.cam_q_model[1], pose.cam_q_model[2],
                                 pose.cam_q_model[3]);
      EXPECT_LT((q.toRotationMatrix() - cam_T_model.R.cast<double>()).norm(), 1e-5) << angle;
    }
  }
}

}  // namespace
}  // namespace sh::protocol
