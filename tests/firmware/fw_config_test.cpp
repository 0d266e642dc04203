#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "firmware/config_keys.hpp"
#include "firmware/fw_config.hpp"
#include "firmware/sim_config.hpp"

namespace sh::fw {
namespace {

Status Parse(const std::string& text, FwConfig* c) {
  return ParseConfig(text.data(), text.size(), c);
}

TEST(FwConfig, ParsesEveryKindOfValue) {
  FwConfig c;
  const Status s = Parse(
      "# comment\n"
      "backend = linux\n"
      "  can_interface=can1   # trailing comment\n"
      "node_id = 42\n"
      "heartbeat_ms = 100\n"
      "calibration = /etc/stereohash/calib.yaml\n"
      "budget_ms = 250\n"
      "free_run_dhz = 300\n"
      "model_mask = 0x5\n"
      "volume_min_mm = -100, -200 300\n"
      "volume_max_mm = 100 200 900\n"
      "gpio_trigger_line = 17\n"
      "gpio_outputs_active_low = true\n"
      "sim_seed = 77\n"
      "sim_camera_fault = drop_right\n"
      "\n",
      &c);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(c.backend, Backend::kLinux);
  EXPECT_STREQ(c.can_interface, "can1");
  EXPECT_EQ(c.node_id, 42);
  EXPECT_EQ(c.heartbeat_ms, 100u);
  EXPECT_STREQ(c.calibration, "/etc/stereohash/calib.yaml");
  EXPECT_EQ(c.budget_ms, 250);
  EXPECT_EQ(c.free_run_dhz, 300);
  EXPECT_EQ(c.model_mask, 5u);
  EXPECT_TRUE(c.volume_set());
  EXPECT_FLOAT_EQ(c.volume_min_mm[1], -200.0f);
  EXPECT_FLOAT_EQ(c.volume_max_mm[2], 900.0f);
  EXPECT_EQ(c.gpio_trigger_line, 17);
  EXPECT_TRUE(c.gpio_outputs_active_low);
  EXPECT_EQ(c.sim_seed, 77u);
  EXPECT_EQ(c.sim_camera_fault, SimCameraFault::kDropRight);
  EXPECT_TRUE(ValidateConfig(c).ok());
}

struct BadCase {
  const char* text;
  const char* expected;  // substring of the message
};

// A component's settings of other types take the listed keys' values, converted; the rest of
// the component is left alone.
struct Component {
  uint8_t node_id = 0;
  uint16_t budget_ms = 0;
  bool record_all = false;
  int untouched = 7;
};
#define TEST_COMPONENT_KEYS(X) X(node_id) X(budget_ms) X(record_all)

TEST(FwConfig, ListedKeysAreCopiedIntoAComponent) {
  FwConfig config;
  const char text[] = "node_id = 42\nbudget_ms = 750\nrecord_all = false\n";
  ASSERT_TRUE(ParseConfig(text, std::strlen(text), &config).ok());
  Component c;
  c.record_all = true;
  STEREOHASH_FW_COPY_KEYS(TEST_COMPONENT_KEYS, config, &c);
  EXPECT_EQ(c.node_id, 42);
  EXPECT_EQ(c.budget_ms, 750);
  EXPECT_FALSE(c.record_all);
  EXPECT_EQ(c.untouched, 7);
}

TEST(FwConfig, ErrorsNameLineAndKey) {
  const BadCase cases[] = {
      {"node_id = 1\nnode_id = 0\n", "line 2: key 'node_id'"},
      {"node_id = 128\n", "1..127"},
      {"heartbeat_ms = fast\n", "line 1: key 'heartbeat_ms'"},
      {"backend = windows\n", "expected linux or sim"},
      {"\n\nbogus_key = 1\n", "line 3: unknown key 'bogus_key'"},
      {"node_id = 2\nnode_id = 3\n", "line 2: key 'node_id' given twice"},
      {"just some words\n", "line 1: expected 'key = value'"},
      {"budget_ms = 5\n", "line 1: key 'budget_ms'"},
      {"free_run_dhz = 301\n", "key 'free_run_dhz'"},
      {"model_mask = 0\n", "key 'model_mask'"},
      {"volume_min_mm = 1 2\n", "three numbers"},
      {"volume_frame = world\n", "expected camera or table"},
      {"table_origin_mm = 1 2 x\n", "three numbers"},
      {"background = grey\n", "expected auto, dark or light"},
      {"mlock = maybe\n", "expected true or false"},
      {"can_interface =\n", "missing value"},
      {"= 3\n", "missing key"},
      {"heartbeat_ms = 5\n", "expected 0 (off) or an integer in 10..10000"},
      {"result_mode = fast\n", "expected stream, pdo or both"},
      {"output_frame = world\n", "expected camera, table or robot"},
      {"camera = usb\n", "expected libcamera, sim or directory"},
      {"serial_number = -1\n", "key 'serial_number'"},
      {"record_max = 0\n", "key 'record_max'"},
      {"tables_crc32 = 123456789\n", "up to 8 hex digits"},
      {"tables_crc32 = -1\n", "key 'tables_crc32'"},
      {"features_crc32 = 0xbeefcafg\n", "key 'features_crc32'"},
      {"features_crc32 = 0x\n", "CRC-32"},
  };
  for (const BadCase& bad : cases) {
    FwConfig c;
    const Status s = Parse(bad.text, &c);
    EXPECT_FALSE(s.ok()) << bad.text;
    EXPECT_NE(std::strstr(s.message(), bad.expected), nullptr)
        << "text: " << bad.text << " message: " << s.message();
  }
}

TEST(FwConfig, CommissioningKeys) {
  FwConfig c = SimDefaults();
  const Status s = Parse(
      "heartbeat_ms = 0\n"
      "result_mode = both\n"
      "serial_number = 0x1234ABCD\n"
      "lss_store = /var/lib/stereohash/node-id\n"
      "camera = directory\n"
      "camera_directory = /data/recorded\n"
      "output_frame = robot\n"
      "handeye = /etc/stereohash/handeye.yaml\n",
      &c);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(c.heartbeat_ms, 0u);
  EXPECT_EQ(c.result_mode, canopen::ResultMode::kBoth);
  EXPECT_EQ(c.serial_number, 0x1234ABCDu);
  EXPECT_STREQ(c.lss_store, "/var/lib/stereohash/node-id");
  EXPECT_EQ(c.camera, CameraSource::kDirectory);
  EXPECT_STREQ(c.camera_directory, "/data/recorded");
  EXPECT_EQ(c.output_frame, OutputFrameKey::kRobot);
  EXPECT_TRUE(ValidateConfig(c).ok());

  const struct {
    const char* text;
    const char* expected;
  } bad[] = {
      {"output_frame = robot\n", "needs 'handeye'"},
      {"camera = directory\n", "needs 'camera_directory'"},
      {"table_file = t.yaml\ntable_origin_mm = 0 0 500\n", "both give the table pose"},
      {"backend = linux\ncamera = libcamera\ncalibration = c.yaml\noutput_frame = table\n",
       "needs the table pose"},
  };
  for (const auto& b : bad) {
    FwConfig v = SimDefaults();
    ASSERT_TRUE(Parse(b.text, &v).ok()) << b.text;
    const Status r = ValidateConfig(v);
    EXPECT_FALSE(r.ok()) << b.text;
    EXPECT_NE(std::strstr(r.message(), b.expected), nullptr) << r.message();
  }
}

TEST(FwConfig, BooleansAreExactlyTrueOrFalse) {
  for (const char* word : {"yes", "no", "on", "off", "1", "0", "True", "FALSE"}) {
    FwConfig c;
    const Status s = Parse(std::string("mlock = ") + word + "\n", &c);
    EXPECT_FALSE(s.ok()) << word;
    EXPECT_NE(std::strstr(s.message(), "expected true or false"), nullptr) << s.message();
  }
  FwConfig c;
  EXPECT_TRUE(c.mono_fallback) << "the one-camera fallback is on unless configured off";
  ASSERT_TRUE(Parse("mlock = false\nsim_print_truth = true\nmono_fallback = false\n", &c).ok());
  EXPECT_FALSE(c.mlock);
  EXPECT_FALSE(c.mono_fallback);
  EXPECT_TRUE(c.sim_print_truth);
}

TEST(FwConfig, ByteOrderMarkIsSkippedAndOtherBytesAreShownEscaped) {
  FwConfig c;
  const Status bom = Parse("\xEF\xBB\xBFnode_id = 9\n", &c);
  ASSERT_TRUE(bom.ok()) << bom.message();
  EXPECT_EQ(c.node_id, 9);
  // Not at the start of the text it is a byte like any other, and shown escaped.
  const Status inner = Parse("node_id = 9\n\xEF\xBB\xBFmlock = true\n", &c);
  ASSERT_FALSE(inner.ok());
  EXPECT_NE(std::strstr(inner.message(), "line 2: unknown key '\\xEF\\xBB\\xBFmlock'"), nullptr)
      << inner.message();
  const Status control = Parse("mlock = tr\x1b[2Jue\n", &c);
  ASSERT_FALSE(control.ok());
  EXPECT_NE(std::strstr(control.message(), "(got 'tr\\x1B[2Jue')"), nullptr) << control.message();
}

TEST(FwConfig, TextWithNulOrOverlongLineIsRefused) {
  FwConfig c;
  const char with_nul[] = "node_id = 1\0\n";
  EXPECT_FALSE(ParseConfig(with_nul, sizeof(with_nul) - 1, &c).ok());
  const std::string long_line = "calibration = " + std::string(1000, 'x') + "\n";
  const Status s = Parse(long_line, &c);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(std::strstr(s.message(), "line 1"), nullptr) << s.message();
}

TEST(FwConfig, ValidationChecksCombinations) {
  FwConfig c;
  c.backend = Backend::kLinux;
  EXPECT_NE(std::strstr(ValidateConfig(c).message(), "'calibration'"), nullptr);
  std::strcpy(c.calibration, "/x.yaml");
  EXPECT_TRUE(ValidateConfig(c).ok());
  c.recognition = RecognitionKind::kTruth;
  EXPECT_FALSE(ValidateConfig(c).ok());
  FwConfig d = SimDefaults();
  EXPECT_TRUE(ValidateConfig(d).ok());
  d.volume_min_mm[0] = 5000;
  EXPECT_FALSE(ValidateConfig(d).ok());
}

// A box over a conveyor: its frame is the table's, placed in the left camera by a rotation
// vector and an origin; the linux backend cannot guess the pose, the simulator takes its rig's.
TEST(FwConfig, TableFrameVolumeNeedsAPoseOnTheBoard) {
  FwConfig c;
  ASSERT_TRUE(Parse("backend = linux\ncalibration = /x.yaml\nvolume_frame = table\n"
                    "volume_min_mm = -300 -300 -3\nvolume_max_mm = 300 300 150\n"
                    "background = light\n",
                    &c)
                  .ok());
  EXPECT_EQ(c.volume_frame, VolumeFrame::kTable);
  EXPECT_EQ(c.background, BackgroundKey::kLight);
  const Status s = ValidateConfig(c);
  EXPECT_NE(std::strstr(s.message(), "table_rotation_deg"), nullptr) << s.message();
  ASSERT_TRUE(Parse("backend = linux\ncalibration = /x.yaml\nvolume_frame = table\n"
                    "table_rotation_deg = 180 0 0\ntable_origin_mm = 0 0 600\n",
                    &c)
                  .ok());
  EXPECT_TRUE(ValidateConfig(c).ok());
  FwConfig sim = SimDefaults();
  sim.volume_frame = VolumeFrame::kTable;
  EXPECT_TRUE(ValidateConfig(sim).ok()) << "the simulator knows its table";
}

TEST(FwConfig, TablePoseMapsTableAxesIntoTheCamera) {
  FwConfig c;
  // Camera 600 mm above the table looking down: table z (up) is camera -z, table y is camera -y.
  ASSERT_TRUE(Parse("table_rotation_deg = 180 0 0\ntable_origin_mm = 10 20 600\n", &c).ok());
  const RigidTransform left_T_table = TablePose(c);
  EXPECT_TRUE(
      (left_T_table * Eigen::Vector3f(0, 0, 100)).isApprox(Eigen::Vector3f(10, 20, 500), 1e-4f));
  EXPECT_TRUE(
      (left_T_table * Eigen::Vector3f(5, 5, 0)).isApprox(Eigen::Vector3f(15, 15, 600), 1e-4f));
  // Transform then invert is the identity.
  const Eigen::Vector3f p(-7, 3, 42);
  EXPECT_TRUE((left_T_table.Inverse() * (left_T_table * p)).isApprox(p, 1e-4f));
  // 90 degrees about z maps table x onto camera y.
  ASSERT_TRUE(Parse("table_rotation_deg = 0 0 90\n", &c).ok());
  EXPECT_TRUE(
      (TablePose(c).R * Eigen::Vector3f::UnitX()).isApprox(Eigen::Vector3f::UnitY(), 1e-5f));
}

TEST(FwConfig, ThreadsAndAutomaticDetection) {
  FwConfig c;
  EXPECT_EQ(c.background, BackgroundKey::kAuto);  // automatic by default
  EXPECT_EQ(c.threads, 0);                        // all cores
  ASSERT_TRUE(Parse("threads = 2\nbackground = light\n", &c).ok());
  EXPECT_EQ(c.threads, 2);
  EXPECT_EQ(c.background, BackgroundKey::kLight);
  FwConfig a;
  ASSERT_TRUE(Parse("background = auto\n", &a).ok());
  EXPECT_EQ(a.background, BackgroundKey::kAuto);
  FwConfig bad;
  EXPECT_FALSE(Parse("threads = 99\n", &bad).ok());
  EXPECT_FALSE(Parse("threads = -1\n", &bad).ok());
  EXPECT_FALSE(Parse("background = grey\n", &bad).ok());
}

TEST(FwConfig, MissingFileIsNotFound) {
  FwConfig c;
  const Status s = LoadConfigFile("/nonexistent/stereohash.conf", &c);
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(std::strstr(s.message(), "/nonexistent/stereohash.conf"), nullptr);
}

TEST(FwConfig, ShippedExamplesParse) {
  // Each on top of its program's defaults.
  FwConfig board;
  Status s = LoadConfigFile("firmware/stereohash-fw.conf.example", &board);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(board.backend, Backend::kLinux);
  FwConfig sim = SimDefaults();
  s = LoadConfigFile("firmware/stereohash-fw-sim.conf.example", &sim);
  EXPECT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(sim.backend, Backend::kSim);
}

// The key table: every default lies in its key's range and reads back as itself, so what --help
// and docs/firmware.md print as a default is a value the parser accepts.
TEST(FwConfigKeys, DefaultsParseBackToThemselves) {
  ASSERT_EQ(ConfigKeyCount(), static_cast<size_t>(ConfigKeyId::kCount));
  for (const FwConfig& defaults : {FwConfig(), SimDefaults()}) {
    for (size_t k = 0; k < ConfigKeyCount(); ++k) {
      const ConfigKey& key = ConfigKeys()[k];
      char text[kConfigPathMax], again[kConfigPathMax];
      FormatConfigValue(key, defaults, text, sizeof(text));
      FwConfig c;
      const Status s = ApplyConfigKey(key, text, &c);
      ASSERT_TRUE(s.ok()) << key.name << " = " << text << ": " << s.message();
      FormatConfigValue(key, c, again, sizeof(again));
      EXPECT_STREQ(text, again) << key.name;
      EXPECT_TRUE(c.Given(static_cast<ConfigKeyId>(k))) << key.name;
      EXPECT_EQ(FindConfigKey(key.name), &key);
      EXPECT_GT(std::strlen(key.help), 0u) << key.name;
    }
  }
  EXPECT_EQ(FindConfigKey("no_such_key"), nullptr);
}

TEST(FwConfigKeys, TypesSayWhatIsAccepted) {
  char type[192];
  FormatConfigType(*FindConfigKey("heartbeat_ms"), type, sizeof(type));
  EXPECT_STREQ(type, "0 (off) or integer 10..10000 ms");
  FormatConfigType(*FindConfigKey("node_id"), type, sizeof(type));
  EXPECT_STREQ(type, "integer 1..127");
  FormatConfigType(*FindConfigKey("background"), type, sizeof(type));
  EXPECT_STREQ(type, "auto | dark | light");
  FormatConfigType(*FindConfigKey("can_interface"), type, sizeof(type));
  EXPECT_STREQ(type, "text, up to 15 characters");
  char value[64];
  FormatConfigValue(*FindConfigKey("model_mask"), FwConfig(), value, sizeof(value));
  EXPECT_STREQ(value, "0xFFFFFFFF");
  FormatConfigValue(*FindConfigKey("volume_min_mm"), FwConfig(), value, sizeof(value));
  EXPECT_STREQ(value, "-1000 -1000 100");
  FormatConfigValue(*FindConfigKey("tables_crc32"), FwConfig(), value, sizeof(value));
  EXPECT_STREQ(value, "0");
  FwConfig pinned;
  ASSERT_TRUE(Parse("tables_crc32 = 0x0000ABCD\nfeatures_crc32 = ebf49a5f\n", &pinned).ok());
  EXPECT_EQ(pinned.tables_crc32, 0xabcdu);
  EXPECT_EQ(pinned.features_crc32, 0xebf49a5fu);
  FormatConfigValue(*FindConfigKey("tables_crc32"), pinned, value, sizeof(value));
  EXPECT_STREQ(value, "0000abcd");  // as `tables info` prints it, and read back alike
}

// Keys given by a file are marked: the volume box and the table pose are "set" by their keys,
// and a box given in the simulator replaces its default one.
TEST(FwConfigKeys, GivenKeysMarkTheBoxAndTheTablePose) {
  FwConfig c;
  EXPECT_FALSE(c.volume_set());
  EXPECT_FALSE(c.table_pose_set());
  ASSERT_TRUE(Parse("volume_max_mm = 1 2 3\ntable_origin_mm = 0 0 500\n", &c).ok());
  EXPECT_TRUE(c.volume_set());
  EXPECT_TRUE(c.table_pose_set());
  EXPECT_TRUE(c.Given(ConfigKeyId::volume_max_mm));
  EXPECT_FALSE(c.Given(ConfigKeyId::volume_min_mm));
  FwConfig sim = SimDefaults();
  EXPECT_TRUE(sim.volume_set());
  EXPECT_TRUE(sim.volume_is_sim_default());
  ASSERT_TRUE(Parse("volume_min_mm = -10 -10 -10\n", &sim).ok());
  EXPECT_TRUE(sim.volume_set());
  EXPECT_FALSE(sim.volume_is_sim_default());
}

// Each program has its own cameras: the board refuses the simulated ones and recorded pairs
// (replayed by stereohash-fw-sim), the simulator refuses libcamera.
TEST(FwConfig, CamerasBelongToTheirProgram) {
  FwConfig board;
  ASSERT_TRUE(
      Parse("calibration = /x.yaml\ncamera = directory\ncamera_directory = /d\n", &board).ok());
  Status s = ValidateConfig(board);
  EXPECT_NE(std::strstr(s.message(), "stereohash-fw-sim"), nullptr) << s.message();
  FwConfig sim = SimDefaults();
  ASSERT_TRUE(Parse("camera = libcamera\n", &sim).ok());
  s = ValidateConfig(sim);
  EXPECT_NE(std::strstr(s.message(), "key 'camera'"), nullptr) << s.message();
  FwConfig replay = SimDefaults();
  ASSERT_TRUE(
      Parse("camera = directory\ncamera_directory = /d\nrecognition = truth\n", &replay).ok());
  s = ValidateConfig(replay);
  EXPECT_NE(std::strstr(s.message(), "recognition = truth"), nullptr) << s.message();
}

}  // namespace
}  // namespace sh::fw
