// The firmware core in-process: boot, triggers from CAN and GPIO, commands, and every fault the
// board must survive, injected through the simulator backends.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "tests/support/firmware_doubles.hpp"

namespace sh::testing {
namespace {

// After a fault: clear-fault brings the no-error EMCY and the ready state back, and a trigger
// with `request_id` produces its result set again.
void ExpectRecoveryByClearFault(Rig& rig, uint16_t request_id) {
  rig.ClearFault();
  ASSERT_TRUE(rig.WaitEmcy(uint16_t(EmcyCode::kNoError)));
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(request_id);
  std::optional<ResultSet> s = rig.WaitSetFor(request_id);
  ASSERT_TRUE(s) << "no set answered request " << request_id;
}

TEST(FirmwareCore, BootsWithBootUpThenOperationalHeartbeats) {
  Rig rig;
  rig.Start();
  std::optional<hal::CanFrame> first = rig.WaitFor(kCobHeartbeat);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->len, 1);
  EXPECT_EQ(first->data[0], 0x00) << "boot-up comes first";
  std::optional<hal::CanFrame> hb = rig.WaitFor(kCobHeartbeat);
  ASSERT_TRUE(hb);
  EXPECT_EQ(hb->data[0], uint8_t(NmtState::kOperational));
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  EXPECT_EQ(rig.core.loaded_models(), rig.data->table().model_count());
  EXPECT_EQ(rig.recognition.inits.load(), 1);
  EXPECT_TRUE(rig.gpio.output(hal::GpioOutput::kReady));
}

TEST(FirmwareCore, CanAndGpioTriggersPublishSequencedResultSets) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.gpio.ClearOutputLog();
  rig.Trigger(77);
  std::optional<CommandAck> ack = rig.WaitAck(0x01);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  EXPECT_EQ(ack->request_id, 77);
  EXPECT_EQ(rig.sets_completed(), 0) << "the ack of a trigger precedes its result set";
  std::optional<ResultSet> a = rig.WaitSet();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->request_id, 77);
  EXPECT_EQ(a->status, ResultStatus::kOk);
  ASSERT_EQ(a->object_count, 1);

  ASSERT_TRUE(rig.gpio.FireTrigger());
  std::optional<ResultSet> b = rig.WaitSet();
  ASSERT_TRUE(b);
  EXPECT_EQ(b->request_id, 0) << "hardware trigger";
  EXPECT_EQ(uint16_t(a->sequence + 1), b->sequence);
  // Consecutive captures: the object's x carries the frame number.
  EXPECT_NEAR(b->objects[0].cam_t_model_mm[0] - a->objects[0].cam_t_model_mm[0], 1.0, 0.01);

  // Strobe pulsed once per trigger, busy raised and lowered.
  hal::GpioOutputChange log[64];
  const size_t n = rig.gpio.CopyOutputLog(log, 64);
  int strobe_on = 0, strobe_off = 0, busy_on = 0;
  for (size_t i = 0; i < n; ++i) {
    if (log[i].output == hal::GpioOutput::kStrobe) (log[i].active ? strobe_on : strobe_off)++;
    if (log[i].output == hal::GpioOutput::kBusy && log[i].active) ++busy_on;
  }
  EXPECT_EQ(strobe_on, 2);
  EXPECT_EQ(strobe_off, 2);
  EXPECT_EQ(busy_on, 2);
  EXPECT_EQ(rig.broken_sets, 0);
}

TEST(FirmwareCore, OutOfRangeCommandsAreRejectedWithEmcyAndChangeNothing) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  const uint16_t budget = rig.core.budget_ms();
  rig.Command({0x03, 5, 0, 0, 0, 0, 0, 0});  // budget 5 ms < 20 ms
  std::optional<CommandAck> ack = rig.WaitAck(0x03);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kOutOfRange));
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kProtocolError));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail, 0x03020005u);
  EXPECT_EQ(e->state, FirmwareState::kReady);
  EXPECT_EQ(rig.core.budget_ms(), budget);

  rig.Command({0x02, 0, 0, 0x10, 0, 0, 0, 0});  // model 20: not loaded
  ack = rig.WaitAck(0x02);
  ASSERT_TRUE(ack);
  EXPECT_NE(ack->status, 0);
  rig.Command({0x05, 0x2D, 0x01, 0, 0, 0, 0, 0});  // 30.1 Hz > 30 Hz
  ack = rig.WaitAck(0x05);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kOutOfRange));
  rig.Command({0x42});  // unknown command
  ack = rig.WaitAck(0x42);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kInvalidArgument));
  rig.Command({0x01});  // trigger without its request id
  ASSERT_TRUE(rig.WaitEmcy(uint16_t(EmcyCode::kPdoLengthError)));
  EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
  EXPECT_EQ(rig.core.model_mask(), (1u << rig.core.loaded_models()) - 1);

  // Valid settings are applied: budget reaches the recognition, the mask too.
  rig.Command({0x03, 0xFA, 0x00, 0, 0, 0, 0, 0});  // 250 ms
  ack = rig.WaitAck(0x03);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->value, 250u);
  rig.Command({0x02, 0x05, 0, 0, 0, 0, 0, 0});
  ack = rig.WaitAck(0x02);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  rig.Trigger(9);
  ASSERT_TRUE(rig.WaitSet());
  EXPECT_EQ(rig.recognition.mask.load(), 5u);
  EXPECT_FLOAT_EQ(rig.recognition.last_budget_ms.load(), 250.0f);
}

TEST(FirmwareCore, CommandCodeZeroIsTheIdleValueAndRunsNothing) {
  // A PLC that clears its command output after each command sends code 0 "on change".
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Command({0x00, 0, 0, 0, 0, 0, 0, 0});
  rig.Command({0x00});
  rig.Command({0x03, 0xFA, 0x00, 0, 0, 0, 0, 0});  // 250 ms
  std::optional<hal::CanFrame> ack = rig.WaitFor(kCobCommandAck, -1);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->data[0], 0x03) << "code 0 is not acknowledged";
  EXPECT_FALSE(rig.WaitEmcy(uint16_t(EmcyCode::kProtocolError), 300));
  EXPECT_FALSE(rig.WaitEmcy(uint16_t(EmcyCode::kPdoLengthError), 10));
  EXPECT_EQ(rig.core.budget_ms(), 250);
}

TEST(FirmwareCore, FreeRunProducesSetsWithRequestIdZeroUntilStopped) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Command({0x05, 200, 0, 0, 0, 0, 0, 0});  // 20 Hz
  for (int i = 0; i < 3; ++i) {
    std::optional<ResultSet> s = rig.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->request_id, 0);
  }
  rig.Command({0x05, 0, 0, 0, 0, 0, 0, 0});
  ASSERT_TRUE(rig.WaitAck(0x05));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  while (rig.WaitSet(50)) {
  }
  EXPECT_FALSE(rig.WaitSet(300)) << "free-run continued after rate 0";
}

TEST(FirmwareCore, CameraTimeoutFaultsKeepsHeartbeatAndClearFaultRecovers) {
  hal::SimCameraConfig cc;
  cc.right_stop_after = 1;  // the right camera goes silent after one frame
  Rig rig(cc);
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(1);
  ASSERT_TRUE(rig.WaitSet());
  rig.Trigger(2);
  std::optional<ResultSet> bad = rig.WaitSet();
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, ResultStatus::kImageError);
  EXPECT_EQ(bad->object_count, 0);
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kSensor));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->state, FirmwareState::kFault);
  EXPECT_EQ(e->detail >> 24, kSensorCaptureFailed >> 24);
  EXPECT_EQ(rig.core.state(), FirmwareState::kFault);
  EXPECT_TRUE(rig.SeeHeartbeats(3)) << "heartbeat continues in fault";

  rig.Trigger(3);  // refused while in fault
  std::optional<CommandAck> ack = rig.WaitAck(0x01);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition));

  rig.ClearFault();  // restarts the camera: one more frame from the right side
  ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  ASSERT_TRUE(rig.WaitEmcy(uint16_t(EmcyCode::kNoError)));
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Trigger(4);
  std::optional<ResultSet> good = rig.WaitSet();
  ASSERT_TRUE(good);
  EXPECT_EQ(good->status, ResultStatus::kOk);
}

TEST(FirmwareCore, UnpairedFramesAreReportedWithoutLosingTheTrigger) {
  hal::SimCameraConfig cc;
  cc.drop_right_every = 2;
  Rig rig(cc);
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  bool warned = false;
  for (int i = 1; i <= 4; ++i) {
    rig.Trigger(uint16_t(i));
    std::optional<ResultSet> s = rig.WaitSet();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->status, ResultStatus::kOk);
  }
  const hal::CameraStats stats = rig.camera->stats();
  ASSERT_GT(stats.left_unpaired_drops + stats.right_unpaired_drops, 0u);
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kSensor), 500);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail >> 24, kSensorUnpairedFrames >> 24);
  warned = true;
  EXPECT_TRUE(warned);
  EXPECT_EQ(rig.core.state(), FirmwareState::kReady);
}

TEST(FirmwareCore, BusOffFaultsThenRecoveryIsReportedAndClearFaultRecovers) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.bus.InjectBusOff(rig.fw);
  ASSERT_TRUE(rig.gpio.FireTrigger());
  EXPECT_TRUE(rig.WaitState(FirmwareState::kFault));
  EXPECT_EQ(rig.CountHeartbeats(150), 0) << "nothing leaves a bus-off controller";
  rig.bus.RecoverFromBusOff(rig.fw);
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kRecoveredFromBusOff));
  ASSERT_TRUE(e);
  EXPECT_GE(e->detail, 1u);
  EXPECT_EQ(e->state, FirmwareState::kFault);
  EXPECT_TRUE(rig.SeeHeartbeats(2)) << "heartbeat resumes after recovery";
  ExpectRecoveryByClearFault(rig, 11);
}

TEST(FirmwareCore, FullTransmitQueueFaultsWithEmcyAndRecovers) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.bus.InjectTxQueueFull(rig.fw, 12);  // two frames' worth of retries
  ASSERT_TRUE(rig.gpio.FireTrigger());
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kCommunication));
  ASSERT_TRUE(e);
  EXPECT_GE(e->detail, 1u) << "dropped frames";
  EXPECT_EQ(rig.core.state(), FirmwareState::kFault);
  EXPECT_TRUE(rig.SeeHeartbeats(2));
  ExpectRecoveryByClearFault(rig, 12);
}

TEST(FirmwareCore, CorruptTablesBootIntoFaultAndRecoverOnceRepaired) {
  Rig rig;
  rig.data->InjectCorruptTables(true);
  rig.Start();
  rig.ExpectBootDataFault(kDetailTables);

  rig.ClearFault();  // still corrupt: refused, fault stays
  std::optional<CommandAck> ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, uint8_t(StatusCode::kFailedPrecondition));
  EXPECT_EQ(rig.core.state(), FirmwareState::kFault);

  rig.data->InjectCorruptTables(false);  // e.g. a good file copied onto the board
  rig.ClearFault();
  ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  EXPECT_EQ(rig.recognition.inits.load(), 1);
  rig.Trigger(5);
  ASSERT_TRUE(rig.WaitSet());
}

// tables_crc32 pins the model set: other tables (a file rebuilt since, another cell's set) are
// a tables fault naming both CRC-32s, the node keeps its heartbeat, and the pinned set clears it.
TEST(FirmwareCore, TablesOtherThanThePinnedOnesAreATablesFault) {
  const uint32_t builtin = BlobHeaderCrc32(DefaultTableBlob(), DefaultTableBlobSize());
  ASSERT_NE(builtin, 0u);
  Rig rig;
  rig.data->PinIdentity(builtin ^ 0x00010000u, 0);
  rig.Start();
  rig.ExpectBootDataFault(kDetailTables);
  const Result<TableView> refused = rig.data->LoadTable();
  ASSERT_FALSE(refused.ok());
  char expected[96];
  std::snprintf(expected, sizeof(expected), "carry CRC-32 %08x, not the %08x that tables_crc32",
                builtin, builtin ^ 0x00010000u);
  EXPECT_NE(std::strstr(refused.status().message(), expected), nullptr)
      << refused.status().message();
  EXPECT_EQ(rig.data->tables_crc32(), 0u);

  rig.data->PinIdentity(builtin, 0);  // the pinned set is what the board now holds
  rig.ClearFault();
  std::optional<CommandAck> ack = rig.WaitAck(0x04);
  ASSERT_TRUE(ack);
  EXPECT_EQ(ack->status, 0);
  EXPECT_TRUE(rig.WaitState(FirmwareState::kReady));
  EXPECT_EQ(rig.data->tables_crc32(), builtin);
}

// A tables file's identity is its header's CRC-32 (what `tables info` prints), whatever the file
// is called. A file that is no feature database is refused as such, before any pin is read.
TEST(FileDataSource, TheIdentityOfATablesFileIsItsHeadersCrc) {
  char path[] = "/tmp/stereohash_fw_tables_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  const auto size = static_cast<ssize_t>(DefaultTableBlobSize());
  ASSERT_EQ(write(fd, DefaultTableBlob(), DefaultTableBlobSize()), size);
  close(fd);
  const uint32_t crc = BlobHeaderCrc32(DefaultTableBlob(), DefaultTableBlobSize());
  const StereoCalibration calib;
  FileDataSource data(path, "", &calib);
  data.PinIdentity(crc, 0);
  EXPECT_TRUE(data.LoadTable().ok());
  EXPECT_EQ(data.tables_crc32(), crc);
  data.SetFeaturesPath(path);  // not a feature database: refused as such before any pin
  data.PinIdentity(crc, 1);
  const Result<FeatureDbView> features = data.LoadFeatures();
  EXPECT_FALSE(features.ok());
  EXPECT_EQ(std::strstr(features.status().message(), "features_crc32"), nullptr)
      << features.status().message();
  std::remove(path);
}

TEST(FirmwareCore, MissingCalibrationBootsIntoFault) {
  Rig rig;
  rig.data->InjectMissingCalibration(true);
  rig.Start();
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kDataSet));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail, kDetailCalibration);
  EXPECT_EQ(rig.core.fault_bits(), uint32_t(kFaultCalibration));
  rig.data->InjectMissingCalibration(false);
  ExpectRecoveryByClearFault(rig, 13);
}

// A calibration file for a 640 x 480 rig with this left focal length.
std::string CalibrationYaml(const char* left_fx) {
  std::string k =
      std::string("K1: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ ") + left_fx +
      ", 0., 320., 0., 500., 240., 0., 0., 1. ]\n";
  const char* rest =
      "D1: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n"
      "K2: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
      "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
      "D2: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]\n"
      "R: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
      "   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]\n"
      "T: !!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ -100., 0., 0. ]\n";
  return "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n" + k + rest;
}

TEST(FirmwareCore, ImplausibleCalibrationFileBootsIntoFaultUntilReplaced) {
  char path[] = "/tmp/stereohash_fw_calib_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  auto write = [&](const std::string& text) {
    FILE* f = std::fopen(path, "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), f), text.size());
    std::fclose(f);
  };
  write(CalibrationYaml("1e30"));  // fx = 1e30 px: no field of view to speak of
  Rig rig;
  rig.data =
      std::make_unique<FileDataSource>("builtin", path, static_cast<RigCalibration*>(nullptr));
  rig.Start();
  std::optional<Emcy> e = rig.WaitEmcy(uint16_t(EmcyCode::kDataSet));
  ASSERT_TRUE(e);
  EXPECT_EQ(e->detail, kDetailCalibration);
  EXPECT_EQ(rig.core.fault_bits(), uint32_t(kFaultCalibration));
  EXPECT_EQ(rig.recognition.inits.load(), 0);
  EXPECT_TRUE(rig.SeeHeartbeats(2));
  write(CalibrationYaml("500."));
  ExpectRecoveryByClearFault(rig, 14);
  close(fd);
  std::remove(path);
}

// A rig calibrated at a sensor size larger than the pipeline's frames (the 640 x 480 rig above
// at 2560 x 1920) gives the calibration of its frames, binned 2 x 2 as the camera delivers them.
TEST(FirmwareCore, ALargeSensorsCalibrationIsThatOfItsBinnedFrames) {
  std::string text = CalibrationYaml("2000.");
  const auto replace_all = [&text](const std::string& from, const std::string& to) {
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
      text.replace(at, from.size(), to);
      at += to.size();
    }
  };
  replace_all("image_width: 640\nimage_height: 480", "image_width: 2560\nimage_height: 1920");
  replace_all("500., 0., 320., 0., 500., 240.", "2000., 0., 1281.5, 0., 2000., 961.5");
  replace_all(", 0., 320., 0., 500., 240.", ", 0., 1281.5, 0., 2000., 961.5");
  char path[] = "/tmp/stereohash_fw_calib_XXXXXX";
  const int fd = mkstemp(path);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(fd);
  FileDataSource data("builtin", path, static_cast<RigCalibration*>(nullptr));
  const Result<StereoCalibration> calib = data.LoadCalibration();
  std::remove(path);
  ASSERT_TRUE(calib.ok()) << calib.status().message();
  for (const CameraIntrinsics* cam : {&calib->left, &calib->right}) {
    EXPECT_EQ(cam->width, 1280);
    EXPECT_EQ(cam->height, 960);
    EXPECT_DOUBLE_EQ(cam->fx, 1000.0);
    EXPECT_DOUBLE_EQ(cam->cx, 640.5);  // (1281.5 + 0.5) / 2 - 0.5
    EXPECT_DOUBLE_EQ(cam->cy, 480.5);
  }
}

TEST(FirmwareCore, RecognitionErrorGivesStatusThreeAndEmcyButStaysReady) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.recognition.fail_next = true;
  rig.Trigger(21);
  std::optional<ResultSet> s = rig.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kInternalError);
  EXPECT_EQ(s->object_count, 0);
  ASSERT_TRUE(rig.WaitEmcy(uint16_t(EmcyCode::kSoftware)));
  rig.Trigger(22);
  s = rig.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, ResultStatus::kOk);
}

TEST(FirmwareCore, NmtStopSilencesCommandsUntilStarted) {
  Rig rig;
  rig.Start();
  ASSERT_TRUE(rig.WaitState(FirmwareState::kReady));
  rig.Nmt(NmtCommand::kStop);
  std::optional<hal::CanFrame> hb = rig.WaitFor(kCobHeartbeat, uint8_t(NmtState::kStopped));
  ASSERT_TRUE(hb);
  rig.Trigger(30);
  EXPECT_FALSE(rig.WaitFor(kCobCommandAck, 0x01, 300)) << "commands ignored when stopped";
  EXPECT_FALSE(rig.WaitSet(100));
  rig.Nmt(NmtCommand::kStart);
  ASSERT_TRUE(rig.WaitFor(kCobHeartbeat, uint8_t(NmtState::kOperational)));
  rig.Trigger(31);
  std::optional<ResultSet> s = rig.WaitSet();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->request_id, 31);
}

}  // namespace
}  // namespace sh::testing
