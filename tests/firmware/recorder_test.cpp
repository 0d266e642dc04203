// The recorder: pairs and results written by the writer thread in the replayable layout, the
// last record_max kept across restarts, and a write error reported as a warning that ends when
// writing works again.
#include "firmware/recorder.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/recorded_settings.hpp"
#include "hal/sim/image_files.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh::fw {
namespace {

class Observer final : public RecorderObserver {
 public:
  void OnRecordFailed(int e) override {
    ++failed;
    last_error = e;
  }
  void OnRecordRecovered() override { ++recovered; }
  std::atomic<int> failed{0}, recovered{0}, last_error{0};
};

bool Exists(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0;
}

std::string ReadText(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

class RecorderTest : public ::testing::Test {
 protected:
  RecorderTest() {
    EXPECT_TRUE(temp_.ok());
    dir_ = temp_.path();
    calib_.left.width = calib_.right.width = 64;
    calib_.left.height = calib_.right.height = 48;
    calib_.left.fx = calib_.left.fy = calib_.right.fx = calib_.right.fy = 60;
    calib_.left.cx = calib_.right.cx = 32;
    calib_.left.cy = calib_.right.cy = 24;
    calib_.right_t_left_mm = Eigen::Vector3d(-120, 0, 0);
    for (int side = 0; side < 2; ++side) pixels_[side].resize(size_t{64} * 48);
  }

  // Pair k: left pixels k + x, right pixels k + y; one object at x = k mm.
  void Submit(Recorder* r, int k) {
    for (int y = 0; y < 48; ++y) {
      for (int x = 0; x < 64; ++x) {
        pixels_[0][y * 64 + x] = uint8_t(k + x);
        pixels_[1][y * 64 + x] = uint8_t(k + y);
      }
    }
    hal::StereoFrame f;
    f.left = ConstGrayView{pixels_[0].data(), 64, 48, 64};
    f.right = ConstGrayView{pixels_[1].data(), 64, 48, 64};
    f.left_timestamp_ns = f.right_timestamp_ns = 1000 + k;
    protocol::ResultSet set;
    set.sequence = uint16_t(k);
    set.object_count = 1;
    set.objects[0].model_id = 1;
    set.objects[0].cam_t_model_mm[0] = k;
    // The ring of slots may be full while the writer works: wait as a test, never in firmware.
    while (!r->Submit(f, set)) usleep(1000);
  }
  std::string Pair(int k) const {
    char name[16];
    std::snprintf(name, sizeof(name), "/%08d", k);
    return dir_ + name;
  }

  sh::testing::TempDir temp_{"recorder"};
  std::string dir_;  // the temporary directory, or a folder in it
  StereoCalibration calib_;
  std::vector<uint8_t> pixels_[2];
  Observer observer_;
};

TEST_F(RecorderTest, KeepsTheLastPairsInTheReplayLayoutAcrossRestarts) {
  const char* names[] = {"cube", "wedge"};
  RecorderConfig c;
  c.directory = dir_ + "/record";  // created by the recorder
  c.max_pairs = 4;
  c.model_names = names;
  c.model_count = 2;
  c.background = "light";
  FwConfig settings;
  settings.background = BackgroundKey::kLight;
  c.settings = RecordedSettings(settings, ModelSetIdentity{});
  RigidTransform rig_T_table;  // looked down on: the table's z axis towards the camera
  rig_T_table.R = Eigen::AngleAxisf(3.14159265f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  rig_T_table.t_mm = Eigen::Vector3f(1.5f, -2.25f, 612.125f);
  c.rig_T_table = &rig_T_table;
  {
    Recorder r;
    ASSERT_TRUE(r.Start(c, calib_, nullptr, &observer_).ok());
    for (int k = 0; k < 7; ++k) Submit(&r, k);
    r.Stop();
    EXPECT_EQ(r.counters().written, 7u);
  }
  dir_ += "/record";
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(Exists(Pair(k))) << k;
  for (int k = 3; k < 7; ++k) {
    ASSERT_TRUE(Exists(Pair(k) + "/left.png")) << k;
    ASSERT_TRUE(Exists(Pair(k) + "/right.png")) << k;
  }
  std::vector<uint8_t> image(size_t{64} * 48);
  const Result<hal::ImageInfo> left = hal::ReadImageFile(
      (Pair(5) + "/left.png").c_str(), hal::PixelFormat::kGray8, image.data(), image.size());
  ASSERT_TRUE(left.ok()) << left.status().message();
  EXPECT_EQ(image[10 * 64 + 7], uint8_t(5 + 7));
  const std::string json = ReadText(Pair(5) + "/result.json");
  EXPECT_NE(json.find("\"sequence\": 5,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"model\": \"wedge\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"t_mm\": [5.0000"), std::string::npos) << json;
  // The preset the results were recognised with, for the pair and for the set's replays.
  EXPECT_NE(json.find("\"background\": \"light\""), std::string::npos) << json;
  EXPECT_NE(ReadText(dir_ + "/settings.conf").find("\nbackground = light\n"), std::string::npos);
  const std::string yaml = ReadText(dir_ + "/calib.yaml");
  const Result<StereoCalibration> back = ParseCalibrationYaml(yaml.data(), yaml.size());
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_DOUBLE_EQ(back->left.fx, 60.0);
  EXPECT_FALSE(Exists(dir_ + "/table.yaml"));
  // The board's own table, for the replay to bound its volume by.
  const std::string rig = ReadText(dir_ + "/rig_table.yaml");
  const Result<RigidTransform> rig_back = ParseTableYaml(rig.data(), rig.size());
  ASSERT_TRUE(rig_back.ok()) << rig_back.status().message();
  EXPECT_EQ(rig_back->t_mm, rig_T_table.t_mm);

  // A restart continues the numbering and still keeps four.
  c.directory = dir_;
  Recorder again;
  ASSERT_TRUE(again.Start(c, calib_, nullptr, &observer_).ok());
  EXPECT_EQ(again.next_index(), 7u);
  Submit(&again, 7);
  Submit(&again, 8);
  again.Stop();
  EXPECT_FALSE(Exists(Pair(4)));
  for (int k = 5; k < 9; ++k) EXPECT_TRUE(Exists(Pair(k))) << k;
  EXPECT_EQ(observer_.failed.load(), 0);
}

TEST_F(RecorderTest, OnOneCameraOnlyTheImageOfTheCameraInUseIsWritten) {
  RecorderConfig c;
  c.directory = dir_;
  Recorder r;
  ASSERT_TRUE(r.Start(c, calib_, nullptr, &observer_).ok());
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) pixels_[1][y * 64 + x] = uint8_t(3 * x + y);
  }
  hal::StereoFrame f;  // the left camera failed: its view is empty
  f.right = ConstGrayView{pixels_[1].data(), 64, 48, 64};
  f.right_timestamp_ns = 77;
  protocol::ResultSet set;
  set.status = protocol::ResultStatus::kMonocular;
  while (!r.Submit(f, set)) usleep(1000);
  hal::StereoFrame nothing;  // neither camera: nothing to record
  EXPECT_FALSE(r.Submit(nothing, set));
  r.Stop();
  EXPECT_EQ(r.counters().written, 1u);
  EXPECT_EQ(r.counters().dropped, 1u);
  EXPECT_FALSE(Exists(Pair(0) + "/left.png"));
  ASSERT_TRUE(Exists(Pair(0) + "/right.png"));
  std::vector<uint8_t> image(size_t{64} * 48);
  const Result<hal::ImageInfo> right = hal::ReadImageFile(
      (Pair(0) + "/right.png").c_str(), hal::PixelFormat::kGray8, image.data(), image.size());
  ASSERT_TRUE(right.ok()) << right.status().message();
  EXPECT_EQ(image[10 * 64 + 7], uint8_t(3 * 7 + 10));
  const std::string json = ReadText(Pair(0) + "/result.json");
  EXPECT_NE(json.find("\"status\": 4"), std::string::npos) << json;
}

TEST_F(RecorderTest, AWriteErrorIsAWarningUntilWritingWorksAgain) {
  RecorderConfig c;
  c.directory = dir_;
  c.max_pairs = 10;
  c.pgm = true;
  // Pair 1's folder cannot be made: a file stands in its place (as a full disk would refuse it).
  std::ofstream(Pair(1)) << "in the way";
  Recorder r;
  ASSERT_TRUE(r.Start(c, calib_, nullptr, &observer_).ok());
  Submit(&r, 0);
  Submit(&r, 1);
  Submit(&r, 2);
  r.Stop();
  EXPECT_EQ(observer_.failed.load(), 1);
  EXPECT_NE(observer_.last_error.load(), 0);
  EXPECT_EQ(observer_.recovered.load(), 1);
  EXPECT_EQ(r.counters().failed, 1u);
  EXPECT_TRUE(Exists(Pair(0) + "/left.pgm"));
  EXPECT_TRUE(Exists(Pair(2) + "/right.pgm"));
}

TEST_F(RecorderTest, UnwritableDirectoryIsAnErrorNamingIt) {
  std::ofstream(dir_ + "/file") << "x";
  RecorderConfig c;
  c.directory = dir_ + "/file/record";
  Recorder r;
  const Status s = r.Start(c, calib_, nullptr, &observer_);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::string(s.message()).find("file/record"), std::string::npos) << s.message();
  EXPECT_EQ(r.start_error(), ENOTDIR) << "the EMCY detail is the real errno";
  for (const char* path : {"/dev/null", "/proc/stereohash-record"}) {
    c.directory = path;
    Recorder other;
    EXPECT_FALSE(other.Start(c, calib_, nullptr, &observer_).ok()) << path;
    EXPECT_NE(other.start_error(), EIO) << path;
    EXPECT_NE(other.start_error(), 0) << path;
  }
}

TEST(ResultJson, ModelNamesAreEscaped) {
  protocol::ResultSet set;
  set.object_count = 1;
  set.objects[0].model_id = 0;
  const char* names[] = {"cu\"be\\x\x01"};
  const int64_t stamps[2] = {0, 0};
  char out[1024];
  ASSERT_GT(FormatResultJson(set, "camera", "dark", names, 1, stamps, out, sizeof(out)), 0u);
  EXPECT_NE(std::string(out).find("\"model\": \"cu\\\"be\\\\x\\u0001\""), std::string::npos) << out;
}

// What a recording's settings.conf says is read back as configuration, and a replay takes each
// setting its own file does not give.
TEST(RecordedSettings, AReplayTakesWhatItsOwnFileDoesNotGive) {
  static FwConfig live, recorded, replay;  // large: off the stack
  const std::string live_text =
      "background = light\nvolume_frame = table\nvolume_min_mm = -150 -100 -5\n"
      "volume_max_mm = 150.5 100 120\ntable_estimate = per_frame\nmono_fallback = false\n"
      "threads = 2\ntables = /opt/cell/models.bin\n";
  ASSERT_TRUE(ParseConfig(live_text.data(), live_text.size(), &live).ok());
  const std::string text = RecordedSettings(live, {0x0badcafe, 0});
  EXPECT_EQ(text.find("threads"), std::string::npos) << text;  // results do not depend on it
  ASSERT_TRUE(ParseConfig(text.data(), text.size(), &recorded).ok()) << text;
  const std::string replay_text = "background = dark\n";
  ASSERT_TRUE(ParseConfig(replay_text.data(), replay_text.size(), &replay).ok());
  TakeRecordedSettings(recorded, &replay);
  EXPECT_EQ(replay.background, BackgroundKey::kDark);  // the replay's own file wins
  EXPECT_EQ(replay.volume_frame, VolumeFrame::kTable);
  EXPECT_TRUE(replay.volume_set());
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(replay.volume_min_mm[k], live.volume_min_mm[k]) << k;
    EXPECT_EQ(replay.volume_max_mm[k], live.volume_max_mm[k]) << k;
  }
  EXPECT_EQ(replay.table_estimate, TableEstimateKey::kPerFrame);
  EXPECT_FALSE(replay.mono_fallback);
  EXPECT_EQ(replay.threads, FwConfig().threads);
  EXPECT_STREQ(replay.tables, "/opt/cell/models.bin");  // the model set recognised with
  EXPECT_STREQ(replay.features, "");            // none given: the tables' own cartons, as recorded
  EXPECT_EQ(replay.tables_crc32, 0x0badcafeu);  // the identity of the set recognised with
  EXPECT_EQ(replay.features_crc32, 0u);
  // Without a working volume the recording names none, and the replay keeps its own.
  const std::string plain = RecordedSettings(FwConfig(), ModelSetIdentity{});
  EXPECT_EQ(plain.find("volume"), std::string::npos);
  EXPECT_NE(plain.find("tables = builtin\n"), std::string::npos);
  EXPECT_EQ(plain.find("features"), std::string::npos);
  EXPECT_EQ(plain.find("crc32"), std::string::npos);  // nothing loaded: nothing pinned
}

// A recording pins the model data it was recognised with: the tables' CRC-32 always, the
// features file's when the configuration named one (else its cartons are the tables' own).
TEST(RecordedSettings, PinsTheIdentityOfTheModelDataItLoaded) {
  static FwConfig live, recorded;
  const std::string live_text = "tables = /opt/cell/models.bin\nfeatures = /opt/cell/f.bin\n";
  ASSERT_TRUE(ParseConfig(live_text.data(), live_text.size(), &live).ok());
  const std::string text = RecordedSettings(live, {0x89abcdef, 0x00001234});
  EXPECT_NE(text.find("tables_crc32 = 89abcdef\n"), std::string::npos) << text;
  EXPECT_NE(text.find("features_crc32 = 00001234\n"), std::string::npos) << text;
  ASSERT_TRUE(ParseConfig(text.data(), text.size(), &recorded).ok()) << text;
  EXPECT_EQ(recorded.tables_crc32, 0x89abcdefu);
  EXPECT_EQ(recorded.features_crc32, 0x1234u);
}

// A replay's own model set wins over the recorded one, as every other recorded key does.
TEST(RecordedSettings, AReplaysOwnModelSetWins) {
  static FwConfig recorded, replay;
  const std::string recorded_text =
      "tables = /opt/cell/models.bin\ntables_crc32 = 11111111\nfeatures = /opt/cell/f.bin\n"
      "features_crc32 = 0x22222222\n";
  ASSERT_TRUE(ParseConfig(recorded_text.data(), recorded_text.size(), &recorded).ok());
  const std::string replay_text = "tables = here.bin\n";
  ASSERT_TRUE(ParseConfig(replay_text.data(), replay_text.size(), &replay).ok());
  TakeRecordedSettings(recorded, &replay);
  EXPECT_STREQ(replay.tables, "here.bin");
  EXPECT_STREQ(replay.features, "/opt/cell/f.bin");
  // A pin travels with its file: the replay's own tables are not held to the recorded CRC-32,
  // the recorded features file is.
  EXPECT_EQ(replay.tables_crc32, 0u);
  EXPECT_EQ(replay.features_crc32, 0x22222222u);
}

}  // namespace
}  // namespace sh::fw
