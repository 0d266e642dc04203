// The firmware core as a CANopen slave, in-process over the simulated bus: SDO access to the
// dictionary, the heartbeat time, the error register with its error resets, the PDO result
// mode, settings and commands by SDO, LSS node-id changes and NMT resets, and the output frame.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "firmware/canopen/od_table.hpp"
#include "firmware/canopen/pdo.hpp"
#include "firmware/le_bytes.hpp"
#include "firmware/node_id_file.hpp"
#include "tests/support/firmware_doubles.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh::testing {
namespace {

using canopen::kCobIdInvalid;

struct SdoReply {
  bool ok = false;     // answered (not timed out)
  uint32_t abort = 0;  // abort code, 0 if none
  uint32_t value = 0;  // expedited upload value
};

// A minimal SDO client on the rig's PLC endpoint (expedited transfers, node `node`).
class SdoClient {
 public:
  SdoClient(Rig* rig, uint8_t node) : rig_(rig), node_(node) {}

  SdoReply Upload(uint16_t index, uint8_t sub) {
    return Exchange({0x40, uint8_t(index), uint8_t(index >> 8), sub, 0, 0, 0, 0});
  }
  SdoReply Download(uint16_t index, uint8_t sub, uint32_t value, int bytes) {
    const uint8_t cs = static_cast<uint8_t>(0x23 | (4 - bytes) << 2);
    return Exchange({cs, uint8_t(index), uint8_t(index >> 8), sub, uint8_t(value),
                     uint8_t(value >> 8), uint8_t(value >> 16), uint8_t(value >> 24)});
  }

 private:
  SdoReply Exchange(std::initializer_list<uint8_t> bytes) {
    hal::CanFrame f;
    f.id = 0x600 + node_;
    for (uint8_t b : bytes) f.data[f.len++] = b;
    EXPECT_TRUE(rig_->plc->Send(f).ok());
    SdoReply r;
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(15);
    while (std::chrono::steady_clock::now() < end) {
      hal::CanFrame in;
      Result<bool> got = rig_->plc->Receive(&in, 20);
      if (!got.ok() || !*got) continue;
      rig_->Feed(in);
      if (in.id != 0x580u + node_) continue;
      r.ok = true;
      if (in.data[0] == 0x80) {
        r.abort = protocol::GetU32(&in.data[4]);
      } else {
        r.value = protocol::GetU32(&in.data[4]);
      }
      return r;
    }
    return r;
  }

  Rig* rig_;
  uint8_t node_;
};

// Collects frames at the PLC until `pred` holds for one (returned) or the time runs out.
template <typename Pred>
std::optional<hal::CanFrame> WaitFrame(Rig& rig, Pred pred, int timeout_ms = 15000) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (std::chrono::steady_clock::now() < end) {
    hal::CanFrame f;
    Result<bool> got = rig.plc->Receive(&f, 20);
    if (!got.ok() || !*got) continue;
    rig.Feed(f);
    if (pred(f)) return f;
  }
  return std::nullopt;
}

TEST(FirmwareCanopen, MandatoryObjectsReadBackOverSdo) {
  Rig rig;
  rig.config.serial_number = 0xC0FFEE01;
  rig.config.hardware_version = "test rig";
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  SdoClient sdo(&rig, Rig::kNode);
  SdoReply r = sdo.Upload(0x1000, 0);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.abort, 0u);
  r = sdo.Upload(0x1001, 0);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.value & 0xFF, 0u) << "no error while ready";
  r = sdo.Upload(0x1017, 0);
  EXPECT_EQ(r.value & 0xFFFF, 20u);
  EXPECT_EQ(sdo.Upload(0x1018, 0).value & 0xFF, 4u);
  EXPECT_EQ(sdo.Upload(0x1018, 1).value, canopen::kVendorId);
  EXPECT_EQ(sdo.Upload(0x1018, 2).value, canopen::kProductCode);
  EXPECT_EQ(sdo.Upload(0x1018, 3).value, canopen::kRevisionNumber);
  EXPECT_EQ(sdo.Upload(0x1018, 4).value, 0xC0FFEE01u);
  EXPECT_EQ(sdo.Upload(0x1014, 0).value, 0x80u + Rig::kNode);
  EXPECT_EQ(sdo.Upload(0x2002, 0).value & 0xFF, rig.core.loaded_models());
  EXPECT_EQ(sdo.Upload(0x2030, 1).value & 0xFF, uint32_t(FirmwareState::kReady));
  EXPECT_EQ(sdo.Upload(0x5555, 0).abort, 0x06020000u);
  EXPECT_EQ(sdo.Download(0x1000, 0, 1, 4).abort, 0x06010002u);
}

TEST(FirmwareCanopen, HeartbeatTimeIsWritableAndZeroStopsIt) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  SdoClient sdo(&rig, Rig::kNode);
  EXPECT_EQ(sdo.Download(0x1017, 0, 5, 2).abort, 0x06090032u) << "5 ms would flood the bus";
  EXPECT_EQ(sdo.Download(0x1017, 0, 10001, 2).abort, 0x06090031u);
  ASSERT_EQ(sdo.Download(0x1017, 0, 0, 2).abort, 0u);
  EXPECT_EQ(rig.core.heartbeat_ms(), 0u);
  rig.CountHeartbeats(100);  // one may have been on its way
  EXPECT_EQ(rig.CountHeartbeats(300), 0) << "heartbeat time 0 switches it off";
  ASSERT_EQ(sdo.Download(0x1017, 0, 30, 2).abort, 0u);
  EXPECT_EQ(rig.core.heartbeat_ms(), 30u);
  EXPECT_TRUE(rig.SeeHeartbeats(3));
  EXPECT_EQ(sdo.Upload(0x1017, 0).value & 0xFFFF, 30u);
}

TEST(FirmwareCanopen, RejectedCommandIsFollowedByAnErrorReset) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Command({0x03, 5, 0, 0, 0, 0, 0, 0});  // budget 5 ms
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kProtocolError));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->error_register, 0x11);
  std::optional<Emcy> reset = rig.WaitEmcy(uint16_t(EmcyCode::kNoError));
  ASSERT_TRUE(reset) << "the manager must see the error go";
  EXPECT_EQ(reset->error_register, 0);
  SdoClient sdo(&rig, Rig::kNode);
  EXPECT_EQ(sdo.Upload(0x1001, 0).value & 0xFF, 0u);
  EXPECT_EQ(sdo.Upload(0x1003, 0).value & 0xFF, 1u);
  EXPECT_EQ(sdo.Upload(0x1003, 1).value, 0x0005u << 16 | 0x8200u);
  ASSERT_EQ(sdo.Download(0x1003, 0, 0, 1).abort, 0u);
  EXPECT_EQ(sdo.Upload(0x1003, 1).value, 0u);
  EXPECT_EQ(sdo.Download(0x1003, 0, 2, 1).abort, 0x06090030u);
}

TEST(FirmwareCanopen, ErrorRegisterFollowsAFaultUntilItIsCleared) {
  Rig rig;
  rig.data->InjectMissingCalibration(true);
  rig.Start();
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kDataSet));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->error_register, 0x81);
  SdoClient sdo(&rig, Rig::kNode);
  EXPECT_EQ(sdo.Upload(0x1001, 0).value & 0xFF, 0x81u);
  EXPECT_EQ(sdo.Upload(0x2030, 2).value, uint32_t(kFaultCalibration));
  rig.data->InjectMissingCalibration(false);
  rig.ClearFault();
  std::optional<Emcy> reset = rig.WaitEmcy(uint16_t(EmcyCode::kNoError));
  ASSERT_TRUE(reset);
  EXPECT_EQ(reset->error_register, 0);
  EXPECT_EQ(sdo.Upload(0x1001, 0).value & 0xFF, 0u);
  EXPECT_EQ(sdo.Upload(0x2030, 1).value & 0xFF, uint32_t(FirmwareState::kReady));
}

// A table_file or handeye the boot could not use: the node comes up (boot-up, heartbeat, SDO) in
// fault with its EMCY, answers no trigger with poses, and keeps the fault through a clear-fault,
// since the files are read at boot only.
TEST(FirmwareCanopen, CellGeometryErrorBootsIntoAFaultThatClearFaultKeeps) {
  Rig rig;
  rig.config.output_frame = canopen::OutputFrame::kRobotBase;
  rig.config.cell_geometry = Status::Error(StatusCode::kInvalidArgument,
                                           "key 'handeye': /etc/stereohash/handeye.yaml: no R_cam");
  rig.Start();
  std::optional<hal::CanFrame> boot_up = rig.WaitFor(kCobHeartbeat, 0x00);
  ASSERT_TRUE(boot_up) << "the node comes up";
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kDataSet));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail, kDetailCellGeometry);
  EXPECT_EQ(e->state, FirmwareState::kFault);
  EXPECT_EQ(e->error_register, 0x81);
  EXPECT_TRUE(rig.SeeHeartbeats(3)) << "heartbeat continues in fault";
  EXPECT_EQ(rig.core.fault_bits(), uint32_t(kFaultCellGeometry));
  SdoClient sdo(&rig, Rig::kNode);
  EXPECT_EQ(sdo.Upload(0x2030, 1).value & 0xFF, uint32_t(FirmwareState::kFault));
  EXPECT_EQ(sdo.Upload(0x2030, 2).value, uint32_t(kFaultCellGeometry));
  EXPECT_EQ(sdo.Upload(0x1001, 0).value & 0xFF, 0x81u);

  rig.Trigger(31);
  std::optional<CommandAck> ack = rig.WaitAck(0x01);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition)) << "trigger refused";
  EXPECT_FALSE(rig.WaitSet(300)) << "no pose while the frame's transform is unknown";
  EXPECT_EQ(rig.sets_completed(), 0);

  rig.ClearFault();
  ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition));
  e = rig.WaitEmcy(uint16_t(EmcyCode::kDataSet));
  ASSERT_TRUE(e) << "the cause's EMCY again";
  EXPECT_EQ(e->detail, kDetailCellGeometry);
  // The refused trigger and clear-fault are events with their error resets: each keeps the
  // fault's register.
  while (std::optional<Emcy> reset = rig.WaitEmcy(uint16_t(EmcyCode::kNoError), 300)) {
    EXPECT_EQ(reset->error_register, 0x81) << "nothing was cleared";
  }
  EXPECT_EQ(rig.core.state(), FirmwareState::kFault);
  EXPECT_EQ(rig.core.fault_bits(), uint32_t(kFaultCellGeometry));
}

TEST(FirmwareCanopen, PdoModeAnswersEachRequestedObjectOfTheLastSet) {
  Rig rig;
  rig.config.result_mode = canopen::ResultMode::kPdo;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(41);
  std::optional<hal::CanFrame> header = rig.WaitFor(kCobResultHeader);
  ASSERT_TRUE(header);
  const uint16_t sequence = protocol::GetU16(&header->data[0]);
  EXPECT_EQ(header->data[2], 1) << "one object";
  // The stream's object and end frames stay off the bus in PDO mode.
  EXPECT_FALSE(WaitFrame(
      rig,
      [](const hal::CanFrame& f) {
        return f.id == kCobResultObject + Rig::kNode || f.id == kCobResultEnd + Rig::kNode;
      },
      200));

  hal::CanFrame request;
  request.id = 0x300 + Rig::kNode;
  request.len = 2;
  request.data[0] = 7;  // counter
  request.data[1] = 0;  // object 0
  ASSERT_TRUE(rig.plc->Send(request).ok());
  hal::CanFrame answer[4];
  const uint32_t ids[4] = {0x1C0u + Rig::kNode, 0x2C0u + Rig::kNode, 0x3C0u + Rig::kNode,
                           0x4C0u + Rig::kNode};
  for (int k = 0; k < 4; ++k) {
    std::optional<hal::CanFrame> f =
        WaitFrame(rig, [&](const hal::CanFrame& in) { return in.id == ids[k]; });
    ASSERT_TRUE(f) << "TPDO" << 5 + k;
    answer[k] = *f;
  }
  EXPECT_EQ(answer[0].data[0], 7);
  EXPECT_EQ(answer[0].data[2], 0) << "status ok";
  EXPECT_EQ(answer[0].data[5], uint8_t(sequence));
  EXPECT_EQ(answer[3].data[6], 7) << "counter again in the last frame";
  // The fake recognition puts the object at x = frame number, z = 500 mm.
  const int32_t x = protocol::GetI32(&answer[1].data[0]);
  const int32_t z = protocol::GetI32(&answer[2].data[0]);
  EXPECT_EQ(z, 50000);
  SdoClient sdo(&rig, Rig::kNode);
  EXPECT_EQ(int32_t(sdo.Upload(0x2200, 4).value), x) << "SDO and PDO give the same value";

  request.data[0] = 8;
  request.data[1] = 1;  // no such object
  ASSERT_TRUE(rig.plc->Send(request).ok());
  std::optional<hal::CanFrame> none =
      WaitFrame(rig, [&](const hal::CanFrame& in) { return in.id == ids[0] && in.data[0] == 8; });
  ASSERT_TRUE(none);
  EXPECT_EQ(none->data[2], 1);
  // Too short a request: EMCY 0x8210, no answer.
  request.len = 1;
  request.data[0] = 9;
  ASSERT_TRUE(rig.plc->Send(request).ok());
  ASSERT_TRUE(rig.WaitEmcy(uint16_t(EmcyCode::kPdoLengthError)));
}

TEST(FirmwareCanopen, ResultModeAndSettingsBySdoReachTheCore) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  SdoClient sdo(&rig, Rig::kNode);
  ASSERT_EQ(sdo.Download(0x2000, 1, 300, 2).abort, 0u);
  EXPECT_EQ(rig.core.budget_ms(), 300);
  EXPECT_EQ(sdo.Download(0x2000, 2, 1u << 20, 4).abort, 0x06090030u) << "model 20 not loaded";
  ASSERT_EQ(sdo.Download(0x2000, 2, 0x3, 4).abort, 0u);
  EXPECT_EQ(rig.core.model_mask(), 3u);
  // Commands change the dictionary too.
  rig.Command({0x03, 0xFA, 0x00, 0, 0, 0, 0, 0});  // 250 ms
  ASSERT_TRUE(rig.WaitAck(0x03));
  EXPECT_EQ(sdo.Upload(0x2000, 1).value & 0xFFFF, 250u);
  // Both modes: stream and answers. TPDO5 becomes valid.
  ASSERT_EQ(sdo.Download(0x2000, 4, 2, 1).abort, 0u);
  EXPECT_EQ(sdo.Upload(0x1804, 1).value & kCobIdInvalid, 0u);
  EXPECT_EQ(sdo.Upload(0x1801, 1).value & kCobIdInvalid, 0u);
  rig.Trigger(3);
  ASSERT_TRUE(rig.WaitSet()) << "the stream still runs in mode both";
  // A command written by SDO runs like one from RPDO1.
  ASSERT_EQ(sdo.Download(0x2020, 2, 55, 4).abort, 0u);
  ASSERT_EQ(sdo.Download(0x2020, 1, 0x01, 1).abort, 0u);
  std::optional<ResultSet> s = rig.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->request_id, 55);
  EXPECT_EQ(sdo.Upload(0x2021, 3).value & 0xFFFF, 55u) << "the ack is in the dictionary";
}

TEST(FirmwareCanopen, CommandsBySdoRunOnlyWhenOperational) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  SdoClient sdo(&rig, Rig::kNode);
  const uint16_t budget = rig.core.budget_ms();
  rig.Nmt(NmtCommand::kEnterPreOperational);
  // The SDO server answers in pre-operational; its reply also shows the NMT command was taken.
  ASSERT_EQ(sdo.Upload(0x1000, 0).abort, 0u);
  ASSERT_EQ(sdo.Download(0x2020, 2, 500, 4).abort, 0u) << "the argument waits for its code";
  EXPECT_EQ(sdo.Download(0x2020, 1, 0x03, 1).abort, 0x08000022u) << "not in this NMT state";
  EXPECT_EQ(sdo.Download(0x2020, 1, 0x00, 1).abort, 0u) << "the idle code is no command";
  EXPECT_EQ(rig.core.budget_ms(), budget);
  rig.Nmt(NmtCommand::kStart);
  ASSERT_EQ(sdo.Upload(0x1000, 0).abort, 0u);
  ASSERT_EQ(sdo.Download(0x2020, 1, 0x03, 1).abort, 0u);
  std::optional<CommandAck> ack = rig.WaitAck(0x03);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->value, 500u);
  EXPECT_EQ(rig.core.budget_ms(), 500);
  EXPECT_EQ(sdo.Upload(0x2021, 4).value, 500u) << "the ack is in the dictionary";
}

TEST(FirmwareCanopen, LssSetsANewNodeIdThatResetCommunicationApplies) {
  char path[] = "/tmp/stereohash_node_id_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  struct Store final : canopen::LssStore {
    explicit Store(const char* p) : path(p) {}
    Status StoreNodeId(uint8_t id) override {
      std::FILE* f = std::fopen(path, "w");
      if (f == nullptr) return Status::Error(StatusCode::kUnavailable, "cannot write");
      std::fprintf(f, "%u\n", id);
      std::fclose(f);
      return Status::Ok();
    }
    const char* path;
  } store(path);
  Rig rig;
  rig.lss_store = &store;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Lss({0x04, 1});  // all nodes: configuration state
  rig.Lss({0x5A});     // inquire vendor id
  ASSERT_TRUE(rig.WaitLss(0x5A));
  rig.Lss({0x11, 9});  // configure node id 9
  std::optional<hal::CanFrame> configured = rig.WaitLss(0x11);
  ASSERT_TRUE(configured);
  EXPECT_EQ(configured->data[1], 0);
  rig.Lss({0x17});  // store configuration
  std::optional<hal::CanFrame> stored = rig.WaitLss(0x17);
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->data[1], 0);
  std::FILE* f = std::fopen(path, "r");
  ASSERT_NE(f, nullptr);
  unsigned saved = 0;
  EXPECT_EQ(std::fscanf(f, "%u", &saved), 1);
  std::fclose(f);
  EXPECT_EQ(saved, 9u);
  rig.Lss({0x04, 0});  // back to waiting
  EXPECT_EQ(rig.core.node_id(), Rig::kNode) << "pending until reset communication";
  rig.Nmt(NmtCommand::kResetCommunication);
  std::optional<hal::CanFrame> boot =
      WaitFrame(rig, [](const hal::CanFrame& f) { return f.id == 0x709 && f.data[0] == 0; });
  ASSERT_TRUE(boot) << "boot-up with the new id";
  EXPECT_EQ(rig.core.node_id(), 9);
  SdoClient sdo9(&rig, 9);
  EXPECT_EQ(sdo9.Upload(0x1014, 0).value, 0x89u) << "COB-IDs follow the new id";
  EXPECT_EQ(sdo9.Upload(0x1200, 1).value, 0x609u);
  std::remove(path);
}

// CiA 305 fastscan from the master's side: each identity part found bit by bit (a slave answers
// while the bits checked so far match), then confirmed; the last confirmation puts the slave
// into the configuration state. Returns false if no slave answered the reset.
bool Fastscan(Rig& rig, uint32_t found[4]) {
  const auto scan = [&](uint32_t id, uint8_t bit, uint8_t sub, uint8_t next) {
    rig.Lss({0x51, uint8_t(id), uint8_t(id >> 8), uint8_t(id >> 16), uint8_t(id >> 24), bit, sub,
             next});
    return rig.WaitLss(0x4F, 100).has_value();
  };
  if (!scan(0, 0x80, 0, 0)) return false;
  for (uint8_t sub = 0; sub < 4; ++sub) {
    uint32_t id = 0;
    for (int bit = 31; bit >= 1; --bit) {
      if (!scan(id, uint8_t(bit), sub, sub)) id |= 1u << bit;
    }
    if (!scan(id, 0, sub, uint8_t((sub + 1) % 4))) id |= 1u;
    if (id & 1u) {
      EXPECT_TRUE(scan(id, 0, sub, uint8_t((sub + 1) % 4))) << "part " << int(sub);
    }
    found[sub] = id;
  }
  return true;
}

TEST(FirmwareCanopen, NodeIdFFMakesTheNodeUnconfiguredUntilFastscanGivesItAnId) {
  char path[] = "/tmp/stereohash_node_id_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  close(fd);
  NodeIdFile store(path);
  Rig rig;
  rig.config.serial_number = 0x5EB1A1u;
  rig.lss_store = &store;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  uint32_t identity[4] = {};
  EXPECT_FALSE(Fastscan(rig, identity)) << "a configured node does not take part";
  rig.Lss({0x04, 1});
  rig.Lss({0x11, 0xFF});
  std::optional<hal::CanFrame> r = rig.WaitLss(0x11);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->data[1], 0);
  rig.Lss({0x17});
  r = rig.WaitLss(0x17);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->data[1], 0) << "0xFF is stored";
  Result<uint8_t> stored = ReadNodeIdFile(path);
  ASSERT_TRUE(stored.ok()) << stored.status().message();
  EXPECT_EQ(*stored, 0xFF);
  rig.Lss({0x04, 0});
  rig.Nmt(NmtCommand::kResetCommunication);
  WaitFrame(
      rig, [](const hal::CanFrame&) { return false; }, 150);  // what was on its way
  // Silent but for LSS: no boot-up, no heartbeat, under no id.
  EXPECT_FALSE(WaitFrame(
      rig, [](const hal::CanFrame& f) { return f.id != canopen::kLssSlaveCobId; }, 500));
  EXPECT_EQ(rig.core.node_id(), 0xFF);

  ASSERT_TRUE(Fastscan(rig, identity)) << "fastscan finds the unconfigured node";
  EXPECT_EQ(identity[0], canopen::kVendorId);
  EXPECT_EQ(identity[1], canopen::kProductCode);
  EXPECT_EQ(identity[2], canopen::kRevisionNumber);
  EXPECT_EQ(identity[3], 0x5EB1A1u);
  rig.Lss({0x11, 12});  // the fastscan left it in the configuration state
  r = rig.WaitLss(0x11);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->data[1], 0);
  rig.Lss({0x04, 0});  // leaving configuration applies the id at once (CiA 305)
  std::optional<hal::CanFrame> boot =
      WaitFrame(rig, [](const hal::CanFrame& f) { return f.id == 0x70C && f.data[0] == 0; });
  ASSERT_TRUE(boot) << "boot-up with the new id";
  EXPECT_EQ(rig.core.node_id(), 12);
  std::remove(path);
}

TEST(FirmwareCanopen, NodeIdFileMessageQuotesTheValueWithoutItsLineEnd) {
  TempDir dir("node_id");
  std::FILE* f = std::fopen(dir.Sub("id").c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs("200\n", f);
  std::fclose(f);
  const Result<uint8_t> id = ReadNodeIdFile(dir.Sub("id").c_str());
  ASSERT_FALSE(id.ok());
  EXPECT_NE(std::string(id.status().message()).find("holds '200', not a node id"),
            std::string::npos)
      << id.status().message();
}

TEST(FirmwareCanopen, ResetNodeRestoresTheConfiguredSettings) {
  Rig rig;
  rig.config.budget_ms = 700;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  SdoClient sdo(&rig, Rig::kNode);
  ASSERT_EQ(sdo.Download(0x2000, 1, 300, 2).abort, 0u);
  ASSERT_EQ(sdo.Download(0x1017, 0, 50, 2).abort, 0u);
  rig.Nmt(NmtCommand::kResetNode, 0);  // all nodes
  ASSERT_TRUE(rig.WaitFor(kCobHeartbeat, 0x00)) << "boot-up";
  EXPECT_EQ(sdo.Upload(0x2000, 1).value & 0xFFFF, 700u);
  EXPECT_EQ(sdo.Upload(0x1017, 0).value & 0xFFFF, 20u);
  EXPECT_EQ(rig.core.budget_ms(), 700);
  EXPECT_EQ(rig.core.heartbeat_ms(), 20u);
}

TEST(FirmwareCanopen, PosesAreReportedInTheConfiguredFrame) {
  Rig rig;
  rig.config.output_frame = canopen::OutputFrame::kRobotBase;
  // Robot base: camera 1 m above, looking down (camera z = -robot z), x axes aligned.
  rig.config.out_T_camera.R << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  rig.config.out_T_camera.t_mm = Eigen::Vector3f(100, 200, 1000);
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(2);
  std::optional<ResultSet> s = rig.WaitSet();
  ASSERT_TRUE(s);
  ASSERT_EQ(s->object_count, 1);
  EXPECT_EQ(s->output_frame, uint8_t(canopen::OutputFrame::kRobotBase));
  // Camera pose (x, 0, 500) with identity rotation -> robot (100 + x, 200, 500).
  EXPECT_NEAR(s->objects[0].cam_t_model_mm[1], 200.0, 0.01);
  EXPECT_NEAR(s->objects[0].cam_t_model_mm[2], 500.0, 0.01);
  const double* q = s->objects[0].cam_q_model;  // 180 deg about x
  EXPECT_NEAR(std::fabs(q[1]), 1.0, 1e-3);
}

}  // namespace
}  // namespace sh::testing

namespace sh::testing {
namespace {

TEST(FirmwareCanopen, RecordingThatCannotBeWrittenIsAWarningNotAFault) {
  const sh::testing::TempDir temp("fw_record");
  ASSERT_TRUE(temp.ok());
  const char* dir = temp.path().c_str();
  // The first pair's folder is taken by a file: its write fails, the next ones work.
  std::FILE* in_the_way = std::fopen((std::string(dir) + "/00000000").c_str(), "w");
  ASSERT_NE(in_the_way, nullptr);
  std::fclose(in_the_way);
  Rig rig;
  for (CameraIntrinsics* cam : {&rig.calib.left, &rig.calib.right}) {
    cam->fx = cam->fy = 60;  // a calibration the recorder can write
    cam->cx = 32;
    cam->cy = 24;
  }
  rig.calib.right_t_left_mm = Eigen::Vector3d(-120, 0, 0);
  Recorder recorder;
  RecorderConfig rc;
  rc.directory = dir;
  ASSERT_TRUE(recorder.Start(rc, rig.calib, nullptr, &rig.core).ok());
  rig.recorder = &recorder;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(1);
  ASSERT_TRUE(rig.WaitSet());
  std::optional<Emcy> warning = rig.WaitEmcy(uint16_t(EmcyCode::kRecording));
  ASSERT_TRUE(warning);
  EXPECT_EQ(warning->error_register, 0x81);
  EXPECT_EQ(warning->state, FirmwareState::kReady) << "a warning, not a fault";
  EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
  rig.Trigger(2);
  ASSERT_TRUE(rig.WaitSet()) << "triggers still work";
  std::optional<Emcy> reset = rig.WaitEmcy(uint16_t(EmcyCode::kNoError));
  ASSERT_TRUE(reset) << "writing works again: error reset";
  EXPECT_EQ(reset->error_register, 0);
  rig.core.Stop();
  recorder.Stop();
  EXPECT_EQ(recorder.counters().written, 1u);
}

}  // namespace
}  // namespace sh::testing
