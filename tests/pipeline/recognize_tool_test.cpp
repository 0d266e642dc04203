// End-to-end test of `stereohash recognize`: a pair rendered by `stereohash render` is
// recognised, the JSON output parsed and compared with the renderer's ground truth; bad input
// gives a clear message and a non-zero exit, never a crash.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "tables/aspect_file.hpp"
#include "tables/table_file.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/tool_run.hpp"
#include "tools/eval/mini_json.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/tablegen/model_set_writer.hpp"

namespace sh {
namespace {

using testing::ToolRun;

ToolRun RunTool(const std::string& args) { return testing::RunTool(STEREOHASH_EXE, args); }

std::string ReadText(const std::string& path) { return testing::ReadFileText(path); }

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

RigidTransform PoseOf(const Json& o) {
  RigidTransform T;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.R(r, c) = static_cast<float>(o["R"][r][c].number);
    T.t_mm[r] = static_cast<float>(o["t"][r].number);
  }
  return T;
}

// Two `recognize --json` outputs report the same models at the same poses, in the same order,
// and at least one object.
void ExpectSameObjects(const std::string& json_a, const std::string& json_b) {
  Json a, b;
  ASSERT_TRUE(JsonReader(ReadText(json_a)).Parse(&a)) << json_a;
  ASSERT_TRUE(JsonReader(ReadText(json_b)).Parse(&b)) << json_b;
  ASSERT_GT(a["objects"].size(), 0u) << json_a;
  ASSERT_EQ(a["objects"].size(), b["objects"].size());
  for (size_t i = 0; i < a["objects"].size(); ++i) {
    EXPECT_EQ(a["objects"][i]["model"].text, b["objects"][i]["model"].text) << i;
    const RigidTransform pa = PoseOf(a["objects"][i]), pb = PoseOf(b["objects"][i]);
    EXPECT_EQ(pa.t_mm, pb.t_mm) << i;
    EXPECT_EQ(pa.R, pb.R) << i;
  }
}

class RecognizeToolTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    temp_ = new testing::TempDir("recognize");
    ASSERT_TRUE(temp_->ok());
    dir_ = &temp_->path();
    const ToolRun r = RunTool("render --out " + *dir_ + " --seed 7 --objects 4 --occlusion some");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  static void TearDownTestSuite() { delete temp_; }
  static std::string Path(const char* name) { return *dir_ + "/" + name; }
  static std::string Inputs(const std::string& calib, const std::string& left,
                            const std::string& right) {
    return "recognize --calib " + calib + " --left " + left + " --right " + right;
  }
  static testing::TempDir* temp_;
  static const std::string* dir_;
};

testing::TempDir* RecognizeToolTest::temp_ = nullptr;
const std::string* RecognizeToolTest::dir_ = nullptr;

TEST_F(RecognizeToolTest, JsonMatchesTheRenderedTruth) {
  const ToolRun r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                            " --json " + Path("out.json") + " --overlay " + Path("overlay.png") +
                            " --overlay-features " + Path("features.png"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("recognised"), std::string::npos) << r.output;

  Json out, truth;
  ASSERT_TRUE(JsonReader(ReadText(Path("out.json"))).Parse(&out)) << ReadText(Path("out.json"));
  ASSERT_TRUE(JsonReader(ReadText(Path("truth.json"))).Parse(&truth));
  auto table = OpenDefaultTable();
  ASSERT_TRUE(table.ok());
  std::vector<Model> models;
  for (uint32_t i = 0; i < table->model_count(); ++i) models.push_back(table->model(i));

  std::vector<TruthObject> expected;
  for (const Json& o : truth["objects"].items) {
    const int m = table->FindModel(o["model"].text.c_str());
    ASSERT_GE(m, 0) << o["model"].text;
    expected.push_back({m, PoseOf(o)});
  }
  std::vector<RecognizedPose> found;
  ASSERT_EQ(out["objects"].type, Json::kArray);
  for (const Json& o : out["objects"].items) {
    const int m = table->FindModel(o["model"].text.c_str());
    ASSERT_GE(m, 0) << "unknown model in output: " << o["model"].text;
    RigidTransform T = PoseOf(o);
    EXPECT_NEAR(T.R.determinant(), 1.0f, 1e-4f);
    EXPECT_TRUE((T.R * T.R.transpose()).isApprox(Eigen::Matrix3f::Identity(), 1e-4f));
    ASSERT_EQ(o["verify"].size(), 2u);
    EXPECT_GT(o["verify"][0].number, 0.0);
    EXPECT_LE(o["verify"][1].number, 1.0);
    EXPECT_GT(o["vote"].number, 0.0);
    found.push_back({m, T});
  }
  const MatchCounts m = MatchToTruth(models, expected, found);
  EXPECT_GE(m.correct, static_cast<int>(expected.size()) / 2)
      << m.correct << " of " << expected.size() << "\n"
      << r.output;
  for (float e : m.translation_errors_mm) EXPECT_LT(e, 10.0f);

  const Json& f = out["features"];
  ASSERT_EQ(f["points2d"].size(), 2u);
  ASSERT_EQ(f["lines2d"].size(), 2u);
  EXPECT_GT(f["points2d"][0].number, 0);
  EXPECT_GT(f["lines2d"][1].number, 0);
  EXPECT_GT(f["lines3d"].number, 0);
  EXPECT_EQ(f["points3d"].type, Json::kNumber);
  const Json& rec = out["recognition"];
  EXPECT_GT(rec["scene_bases_tried"].number, 0);
  EXPECT_EQ(rec["held_back"].type, Json::kNumber);
  EXPECT_LE(rec["held_back_accepted"].number, rec["held_back"].number);
  const Json& t = out["time_ms"];
  EXPECT_EQ(out["detection"]["mode"].text, "automatic");
  ASSERT_EQ(out["detection"]["noise_sigma"].size(), 2u);
  // The renderer's sensor noise is 1.5 grey levels (plus the rounding to 8 bits).
  EXPECT_NEAR(out["detection"]["noise_sigma"][0].number, 1.55, 0.2);
  EXPECT_GT(out["detection"]["canny_thresholds"][1][1].number,
            out["detection"]["canny_thresholds"][1][0].number);
  // The renderer's plain table is no texture: no block raises the Canny thresholds.
  EXPECT_GT(out["detection"]["blocks"].number, 100);
  ASSERT_EQ(out["detection"]["textured_blocks"].size(), 2u);
  EXPECT_EQ(out["detection"]["textured_blocks"][0].number, 0);
  EXPECT_EQ(out["detection"]["textured_blocks"][1].number, 0);
  EXPECT_GE(out["threads"].number, 1);
  for (const char* stage : {"features", "stereo", "hashing", "verify", "refine"}) {
    EXPECT_EQ(t[stage].type, Json::kNumber) << stage;
    EXPECT_GE(t[stage].number, 0.0) << stage;
    EXPECT_LE(t[stage].number, t["total"].number + 1e-3) << stage;
  }

  // Both overlays are RGB PNGs of both images side by side.
  auto calib_text = ReadText(Path("calib.yaml"));
  const size_t w_at = calib_text.find("image_width:");
  ASSERT_NE(w_at, std::string::npos);
  const int width = std::atoi(calib_text.c_str() + w_at + 12);
  for (const char* name : {"overlay.png", "features.png"}) {
    const std::string png = ReadText(Path(name));
    ASSERT_GT(png.size(), 33u) << name;
    EXPECT_EQ(png.substr(1, 3), "PNG") << name;
    const auto be32 = [&](size_t at) {
      return (uint32_t(uint8_t(png[at])) << 24) | (uint32_t(uint8_t(png[at + 1])) << 16) |
             (uint32_t(uint8_t(png[at + 2])) << 8) | uint32_t(uint8_t(png[at + 3]));
    };
    EXPECT_EQ(be32(16), uint32_t(2 * width)) << name;
    EXPECT_EQ(uint8_t(png[25]), 2) << name;  // colour type RGB
  }
}

// `render --scenes-per-row` writes a set in the recorded sets' layout: one calibration and table
// pose, six rows of scenes in the grid's order, each object's visible fraction per image, and
// colour PNGs for colour parts (grey ones for plain models).
TEST_F(RecognizeToolTest, RenderWritesAColourSetInTheRecordedLayout) {
  const std::string set = Path("colour_set");
  const ToolRun r = RunTool("render --out " + set +
                            " --models models/colour --scenes-per-row 1 --objects 2 --seed 9");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote 6 scenes"), std::string::npos) << r.output;
  EXPECT_FALSE(ReadText(set + "/calib.yaml").empty());
  EXPECT_FALSE(ReadText(set + "/table.yaml").empty());
  const char* rows[6][2] = {{"dark", "none"},  {"dark", "some"},  {"dark", "severe"},
                            {"light", "none"}, {"light", "some"}, {"light", "severe"}};
  const std::vector<std::string> names = {"bracket",  "can",  "cube",      "hexagon",
                                          "pentagon", "star", "trapezium", "wedge"};
  std::vector<uint8_t> pixels(size_t{756} * 581 * 3);
  for (int i = 0; i < 6; ++i) {
    char scene[64];
    std::snprintf(scene, sizeof(scene), "%s/scene%02d/", set.c_str(), i);
    Json truth;
    ASSERT_TRUE(JsonReader(ReadText(std::string(scene) + "truth.json")).Parse(&truth)) << scene;
    EXPECT_EQ(truth["background"].text, rows[i][0]) << scene;
    EXPECT_EQ(truth["occlusion"].text, rows[i][1]) << scene;
    ASSERT_EQ(truth["objects"].size(), 2u) << scene;
    for (const Json& o : truth["objects"].items) {
      EXPECT_NE(std::find(names.begin(), names.end(), o["model"].text), names.end());
      ASSERT_EQ(o["visible"].size(), 2u);
      for (int k = 0; k < 2; ++k) {
        EXPECT_GE(o["visible"][k].number, 0.0);
        EXPECT_LE(o["visible"][k].number, 1.0);
      }
    }
    const Result<hal::ImageInfo> left =
        hal::ReadImageFile((std::string(scene) + "left.png").c_str(), hal::PixelFormat::kRgb8,
                           pixels.data(), pixels.size());
    ASSERT_TRUE(left.ok()) << left.status().message();
    EXPECT_EQ(left->file_channels, 3) << scene;
  }
  // Plain models (the suite's pair): grey images.
  const Result<hal::ImageInfo> info = hal::ReadImageFile(
      Path("left.png").c_str(), hal::PixelFormat::kRgb8, pixels.data(), pixels.size());
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->file_channels, 1);
}

TEST_F(RecognizeToolTest, MissingFileIsAClearError) {
  const ToolRun r =
      RunTool(Inputs(Path("calib.yaml"), Path("no_such_left.png"), Path("right.png")));
  EXPECT_FALSE(r.signalled);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no_such_left.png"), std::string::npos) << r.output;
  const ToolRun c = RunTool(Inputs(Path("missing.yaml"), Path("left.png"), Path("right.png")));
  EXPECT_NE(c.exit_code, 0);
  EXPECT_NE(c.output.find("missing.yaml"), std::string::npos) << c.output;
  const ToolRun t = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                            " --tables " + Path("no_tables.bin"));
  EXPECT_NE(t.exit_code, 0);
  EXPECT_NE(t.output.find("no_tables.bin"), std::string::npos) << t.output;
}

TEST_F(RecognizeToolTest, MalformedYamlIsAClearError) {
  WriteText(Path("bad.yaml"), "%YAML:1.0\n---\nimage_width: 756\nK1: [not a matrix\n");
  ToolRun r = RunTool(Inputs(Path("bad.yaml"), Path("left.png"), Path("right.png")));
  EXPECT_FALSE(r.signalled);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("bad.yaml"), std::string::npos) << r.output;

  // Non-finite numbers: the focal length replaced by NaN.
  std::string calib = ReadText(Path("calib.yaml"));
  const size_t data = calib.find("data: [", calib.find("K1"));
  ASSERT_NE(data, std::string::npos);
  const size_t comma = calib.find(',', data);
  calib.replace(data + 7, comma - (data + 7), " .nan");
  WriteText(Path("nan.yaml"), calib);
  r = RunTool(Inputs(Path("nan.yaml"), Path("left.png"), Path("right.png")));
  EXPECT_FALSE(r.signalled);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("nan.yaml"), std::string::npos) << r.output;

  // A repeated option would silently keep its last value.
  r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) + " --left " +
              Path("right.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--left given twice"), std::string::npos) << r.output;
  // A directory where an image belongs.
  r = RunTool(Inputs(Path("calib.yaml"), *dir_, Path("right.png")));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("is a directory, not a regular file"), std::string::npos) << r.output;

  r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) + " --budget-ms nan");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = RunTool("recognize --left " + Path("left.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

// The rendered calibration with `from` (a number as the writer prints it) replaced.
std::string CalibrationWith(const std::string& calib, const std::string& from,
                            const std::string& to) {
  std::string text = calib;
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST_F(RecognizeToolTest, ImplausibleCalibrationIsRefusedNamingTheValue) {
  const std::string calib = ReadText(Path("calib.yaml"));
  struct Case {
    const char* from;
    const char* to;
    const char* expected;
  };
  const Case cases[] = {
      {"[ 1136.4000000000001,", "[ 1e-30,", "fx = 1e-30 px"},
      {"[ 1136.4000000000001,", "[ 1e30,", "fx = 1e+30 px"},
      {"379.19999999999999", "5000.", "principal point (5000, 289.6)"},
      {"[ -0.10000000000000001,", "[ 1e6,", "k1=1e+06"},
      {"0.00020000000000000001, -0.0001,\n       0. ]",
       "0.00020000000000000001, -0.0001,\n "
       "      -10353. ]",
       "k3=-10353"},
      {"[ -118.67234802246094,", "[ -1606.,", "baseline 1606 mm"},
  };
  for (const Case& c : cases) {
    WriteText(Path("implausible.yaml"), CalibrationWith(calib, c.from, c.to));
    const ToolRun r =
        RunTool(Inputs(Path("implausible.yaml"), Path("left.png"), Path("right.png")));
    EXPECT_FALSE(r.signalled) << c.to;
    EXPECT_EQ(r.exit_code, 1) << c.to << "\n" << r.output;
    EXPECT_NE(r.output.find(c.expected), std::string::npos) << c.to << "\n" << r.output;
  }
}

TEST_F(RecognizeToolTest, SizeMismatchIsAClearError) {
  std::vector<uint8_t> small(size_t{320} * 240, 40);
  ASSERT_TRUE(
      hal::WritePgm(Path("small.pgm").c_str(), ConstGrayView{small.data(), 320, 240, 320}).ok());
  const ToolRun r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("small.pgm")));
  EXPECT_FALSE(r.signalled);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("320x240"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("calibration"), std::string::npos) << r.output;
  // Not an image at all.
  WriteText(Path("garbage.png"), "this is not an image");
  const ToolRun g = RunTool(Inputs(Path("calib.yaml"), Path("garbage.png"), Path("right.png")));
  EXPECT_FALSE(g.signalled);
  EXPECT_NE(g.exit_code, 0);
  EXPECT_NE(g.output.find("garbage.png"), std::string::npos) << g.output;
}

// A camera larger than a pipeline frame: the pair scaled up 2 x 2 (each pixel repeated) with its
// calibration scaled alike, as a 5 MP sensor would see the scene. `recognize` bins both back
// exactly, so it reports the same objects at the same poses as from the pair itself.
TEST_F(RecognizeToolTest, ALargeSensorsPairIsBinnedWithItsCalibration) {
  const std::string calib_text = ReadText(Path("calib.yaml"));
  Result<StereoCalibration> calib = ParseCalibrationYaml(calib_text.data(), calib_text.size());
  ASSERT_TRUE(calib.ok()) << calib.status().message();
  StereoCalibration big = *calib;
  for (CameraIntrinsics* cam : {&big.left, &big.right}) {
    cam->width *= 2, cam->height *= 2;
    cam->fx *= 2, cam->fy *= 2;
    cam->cx = (cam->cx + 0.5) * 2 - 0.5;
    cam->cy = (cam->cy + 0.5) * 2 - 0.5;
  }
  ASSERT_LE(big.left.width, kMaxSensorWidth);
  ASSERT_GT(big.left.width, kMaxImageWidth);
  std::vector<char> yaml(kMaxCalibrationYamlBytes);
  const Result<size_t> n = WriteCalibrationYaml(big, yaml.data(), yaml.size());
  ASSERT_TRUE(n.ok()) << n.status().message();
  WriteText(Path("big_calib.yaml"), std::string(yaml.data(), *n));
  for (const char* side : {"left", "right"}) {
    const std::string from = Path(side) + ".png", to = Path("big_") + side + ".png";
    std::vector<uint8_t> px(kMaxImagePixels);
    const Result<hal::ImageInfo> info =
        hal::ReadImageFile(from.c_str(), hal::PixelFormat::kGray8, px.data(), px.size());
    ASSERT_TRUE(info.ok()) << info.status().message();
    const int w = info->width, h = info->height;
    std::vector<uint8_t> up(static_cast<size_t>(4) * w * h);
    for (int y = 0; y < 2 * h; ++y) {
      for (int x = 0; x < 2 * w; ++x)
        up[static_cast<size_t>(y) * 2 * w + x] = px[(y / 2) * w + x / 2];
    }
    ASSERT_TRUE(hal::WritePng(to.c_str(), ConstGrayView{up.data(), 2 * w, 2 * h, 2 * w}).ok());
  }
  const ToolRun small = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                                " --threads 1 --json " + Path("small.json"));
  const ToolRun large =
      RunTool(Inputs(Path("big_calib.yaml"), Path("big_left.png"), Path("big_right.png")) +
              " --threads 1 --json " + Path("large.json"));
  ASSERT_EQ(small.exit_code, 0) << small.output;
  ASSERT_EQ(large.exit_code, 0) << large.output;
  EXPECT_NE(large.output.find("binned 2 x 2 to"), std::string::npos) << large.output;
  EXPECT_EQ(small.output.find("binned"), std::string::npos) << small.output;
  ExpectSameObjects(Path("small.json"), Path("large.json"));
}

TEST_F(RecognizeToolTest, TableFileBoundsTheVolumeAndIsReported) {
  const ToolRun r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                            " --table " + Path("table.yaml") + " --json " + Path("table.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Json with_table, without;
  ASSERT_TRUE(JsonReader(ReadText(Path("table.json"))).Parse(&with_table));
  EXPECT_EQ(with_table["table"]["source"].text, "file");
  EXPECT_EQ(with_table["table"]["file"].text, Path("table.yaml"));
  ASSERT_EQ(with_table["table"]["t"].size(), 3u);
  EXPECT_GT(with_table["table"]["t"][2].number, 0.0);  // the table lies in front of the camera
  const ToolRun n = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                            " --json " + Path("no_table.json"));
  ASSERT_EQ(n.exit_code, 0) << n.output;
  ASSERT_TRUE(JsonReader(ReadText(Path("no_table.json"))).Parse(&without));
  // Without the file the table is estimated from the objects standing on it, close to the file's.
  ASSERT_EQ(without["table"]["source"].text, "estimated") << ReadText(Path("no_table.json"));
  EXPECT_EQ(without["table"]["estimate"].text, "accepted");
  EXPECT_GE(without["table"]["resting"].number, 2.0);
  ASSERT_EQ(without["table"]["normal"].size(), 3u);
  double cos_normals = 0;
  for (size_t i = 0; i < 3; ++i) {
    cos_normals += without["table"]["normal"][i].number * with_table["table"]["R"][i][2].number;
  }
  EXPECT_GT(cos_normals, std::cos(1.0 * 3.14159265 / 180.0));  // within 1 deg
  EXPECT_GT(without["table"]["camera_height_mm"].number, 100.0);
  // The volume over the table holds no more 3-D lines than the default box (the estimate's
  // scene plus what it dropped).
  EXPECT_LE(with_table["features"]["lines3d"].number,
            without["features"]["lines3d"].number + without["table"]["dropped"].number);

  WriteText(Path("bad_table.yaml"), "%YAML:1.0\n---\nR_table: 7\n");
  const ToolRun b = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) +
                            " --table " + Path("bad_table.yaml"));
  EXPECT_FALSE(b.signalled);
  EXPECT_EQ(b.exit_code, 1) << b.output;
  EXPECT_NE(b.output.find("bad_table.yaml"), std::string::npos) << b.output;
  EXPECT_NE(b.output.find("R_table"), std::string::npos) << b.output;
}

// One or two threads give the same objects and poses: the parallel features are the same.
TEST_F(RecognizeToolTest, ThreadsDoNotChangeTheResult) {
  Json one, two;
  for (const char* n : {"1", "2"}) {
    const ToolRun r =
        RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) + " --threads " +
                n + " --json " + Path(n[0] == '1' ? "t1.json" : "t2.json"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  ASSERT_TRUE(JsonReader(ReadText(Path("t1.json"))).Parse(&one));
  ASSERT_TRUE(JsonReader(ReadText(Path("t2.json"))).Parse(&two));
  EXPECT_EQ(one["threads"].number, 1);
  EXPECT_EQ(two["threads"].number, 2);
  ASSERT_EQ(one["objects"].size(), two["objects"].size());
  for (size_t i = 0; i < one["objects"].size(); ++i) {
    EXPECT_EQ(one["objects"][i]["model"].text, two["objects"][i]["model"].text);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(one["objects"][i]["t"][k].number, two["objects"][i]["t"][k].number);
    }
  }
  EXPECT_EQ(
      RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) + " --threads 99")
          .exit_code,
      2);
}

// One image: only --left (or only --right) with the table runs the monocular mode, whose poses
// (left camera frame) match the rendered truth; a camera named without its image is refused.
TEST_F(RecognizeToolTest, OneCameraWithTheTableFindsRestingObjects) {
  auto table = OpenDefaultTable();
  ASSERT_TRUE(table.ok());
  std::vector<Model> models;
  for (uint32_t i = 0; i < table->model_count(); ++i) models.push_back(table->model(i));
  Json truth;
  ASSERT_TRUE(JsonReader(ReadText(Path("truth.json"))).Parse(&truth));
  std::vector<TruthObject> expected;
  for (const Json& o : truth["objects"].items) {
    expected.push_back({table->FindModel(o["model"].text.c_str()), PoseOf(o)});
  }
  for (const char* camera : {"left", "right"}) {
    const std::string json = Path(camera) + "_mono.json";
    const ToolRun r = RunTool("recognize --calib " + Path("calib.yaml") + " --" + camera + " " +
                              Path(camera[0] == 'l' ? "left.png" : "right.png") + " --table " +
                              Path("table.yaml") + " --json " + json);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(std::string("monocular (") + camera), std::string::npos) << r.output;
    Json out;
    ASSERT_TRUE(JsonReader(ReadText(json)).Parse(&out)) << ReadText(json);
    EXPECT_EQ(out["mode"].text, "monocular");
    EXPECT_EQ(out["camera"].text, camera);
    EXPECT_EQ(out["frame"].text, "camera");
    std::vector<RecognizedPose> found;
    for (const Json& o : out["objects"].items) {
      const int m = table->FindModel(o["model"].text.c_str());
      ASSERT_GE(m, 0) << "unknown model in output: " << o["model"].text;
      found.push_back({m, PoseOf(o)});
    }
    const MatchCounts m = MatchToTruth(models, expected, found, 5.0f, 5.0f);
    EXPECT_GE(m.correct * 2, static_cast<int>(expected.size()))
        << camera << ": " << m.correct << " of " << expected.size() << "\n"
        << r.output;
  }
  const ToolRun missing = RunTool("recognize --calib " + Path("calib.yaml") + " --left " +
                                  Path("left.png") + " --monocular right");
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("needs the right image"), std::string::npos) << missing.output;
}

// One image without the table plane: refused with the reason and the remedy, no poses guessed.
TEST_F(RecognizeToolTest, OneCameraWithoutTheTableIsRefused) {
  const ToolRun r = RunTool("recognize --calib " + Path("calib.yaml") + " --left " +
                            Path("left.png") + " --json " + Path("no_plane.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("without the table plane"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--table TABLE.yaml"), std::string::npos) << r.output;
  EXPECT_NE(access(Path("no_plane.json").c_str(), F_OK), 0);
}

// A model set given to one camera is used or refused: never the built-in table in its place.
TEST_F(RecognizeToolTest, OneCameraRefusesAModelSetWithoutAnAspectTable) {
  const std::string set = Path("cube_only.bin");
  const ToolRun built =
      RunTool("tables build --models models --names cube --no-hash-2d --out " + set);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  for (const std::string& tables : {set, std::string("/etc/passwd")}) {
    const ToolRun r = RunTool("recognize --tables " + tables + " --calib " + Path("calib.yaml") +
                              " --left " + Path("left.png"));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("--tables " + tables + " holds no aspect table"), std::string::npos)
        << r.output;
  }
}

// A set built from a folder of one's own polyhedra (no models.txt, no option) carries their
// aspect table, so that the one-image rescue runs with it; without it (--no-hash-2d) the rescue
// is off, and said.
TEST_F(RecognizeToolTest, OwnModelSetKeepsTheOneImageRescue) {
  const std::string dir = Path("own_models");
  ASSERT_EQ(mkdir(dir.c_str(), 0777), 0);
  for (const char* m : {"wedge", "cube"}) {
    std::string copy = dir;
    copy.append("/").append(m).append(".obj");
    std::string source = "models/";
    source.append(m).append(".obj");
    WriteText(copy, ReadText(source));
  }
  const std::string stereo = Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png"));
  const ToolRun built = RunTool("tables build --models " + dir + " --out " + Path("own.bin"));
  ASSERT_EQ(built.exit_code, 0) << built.output;
  EXPECT_NE(built.output.find("ASPECTS_2D"), std::string::npos) << built.output;
  const ToolRun with = RunTool(stereo + " --tables " + Path("own.bin"));
  ASSERT_EQ(with.exit_code, 0) << with.output;
  EXPECT_NE(with.output.find("one-image rescue on"), std::string::npos) << with.output;
  EXPECT_EQ(with.output.find("one-image rescue off"), std::string::npos) << with.output;

  const ToolRun plain =
      RunTool("tables build --models " + dir + " --no-hash-2d --out " + Path("own_plain.bin"));
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(plain.output.find("ASPECTS_2D"), std::string::npos) << plain.output;
  const ToolRun without = RunTool(stereo + " --tables " + Path("own_plain.bin"));
  ASSERT_EQ(without.exit_code, 0) << without.output;
  EXPECT_NE(without.output.find("one-image rescue off"), std::string::npos) << without.output;
  EXPECT_EQ(RunTool("tables build --models " + dir + " --no-hash-2d --hash-2d affine --out " +
                    Path("both.bin"))
                .exit_code,
            2);
}

// The poses of a JSON result, in order, as text (model and translation to the printed digits).
std::string PosesText(const std::string& path) {
  Json out;
  if (!JsonReader(ReadText(path)).Parse(&out)) return "unreadable " + path;
  std::string text;
  for (const Json& o : out["objects"].items) {
    text += o["model"].text;
    for (int k = 0; k < 3; ++k) text += " " + std::to_string(o["t"][k].number);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) text += " " + std::to_string(o["R"][r][c].number);
    text += "\n";
  }
  return text;
}

// One model-set file (the built-in hash tables and aspect table as its sections) gives the
// stereo and the one-camera paths their data: the same poses as the separate blobs.
TEST_F(RecognizeToolTest, OneModelSetGivesEveryPathItsSection) {
  Result<std::vector<uint8_t>> set =
      BuildModelSet({{uint32_t(SectionKind::kHash3d),
                      static_cast<const uint8_t*>(DefaultTableBlob()), DefaultTableBlobSize()},
                     {uint32_t(SectionKind::kAspects2d),
                      static_cast<const uint8_t*>(DefaultAspectBlob()), DefaultAspectBlobSize()}});
  ASSERT_TRUE(set.ok()) << set.status().message();
  WriteText(Path("set.bin"), std::string(set->begin(), set->end()));
  WriteText(Path("tables.bin"),
            std::string(static_cast<const char*>(DefaultTableBlob()), DefaultTableBlobSize()));
  WriteText(Path("aspects.bin"),
            std::string(static_cast<const char*>(DefaultAspectBlob()), DefaultAspectBlobSize()));
  const std::string stereo = Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png"));
  ToolRun r = RunTool(stereo + " --tables " + Path("tables.bin") + " --json " + Path("bare.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool(stereo + " --tables " + Path("set.bin") + " --json " + Path("set.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(PosesText(Path("bare.json")).empty());
  EXPECT_EQ(PosesText(Path("set.json")), PosesText(Path("bare.json")));

  const std::string mono = "recognize --calib " + Path("calib.yaml") + " --left " +
                           Path("left.png") + " --table " + Path("table.yaml");
  r = RunTool(mono + " --aspects " + Path("aspects.bin") + " --json " + Path("mono_bare.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool(mono + " --tables " + Path("set.bin") + " --json " + Path("mono_set.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(PosesText(Path("mono_bare.json")).empty());
  EXPECT_EQ(PosesText(Path("mono_set.json")), PosesText(Path("mono_bare.json")));

  // A damaged set, or one without the section a path needs, is refused naming the problem.
  std::string damaged(set->begin(), set->end());
  damaged[damaged.size() / 3] ^= 0x08;
  WriteText(Path("damaged.bin"), damaged);
  r = RunTool(stereo + " --tables " + Path("damaged.bin"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("model set corrupt"), std::string::npos) << r.output;
  r = RunTool(stereo + " --views " + Path("set.bin"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("no SHAPE_VIEWS section"), std::string::npos) << r.output;
}

// Colour parts given grey images: said, not a silent "0 objects".
TEST_F(RecognizeToolTest, ColourPartsInGreyImagesAreWarnedAbout) {
  const std::string stereo = Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png"));
  const ToolRun r = RunTool(stereo + " --views tests/fuzz/corpus/shape_views/wedge_30deg.bin");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: the model set holds 1 colour parts, but the images are grey"),
            std::string::npos)
      << r.output;
}

// `bench recorded` on a folder in the recorded-set layout made of two rendered scenes.
TEST_F(RecognizeToolTest, BenchRecordedScoresAFolderOfScenes) {
  const std::string set = Path("set");
  ASSERT_EQ(mkdir(set.c_str(), 0777), 0);
  for (const char* scene : {"scene00", "scene01"}) {
    const std::string seed = scene[6] == '0' ? "11" : "12";
    std::string command = "render --out ";
    command.append(set).append("/").append(scene).append(" --seed ").append(seed);
    const ToolRun r = RunTool(command + " --objects 3 --occlusion none");
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  // One calibration and table for the set (the camera does not move between scenes).
  WriteText(set + "/calib.yaml", ReadText(set + "/scene00/calib.yaml"));
  const ToolRun r = RunTool("bench recorded " + set + " --json " + Path("bench.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("recall by visibility"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("table: none"), std::string::npos) << r.output;
  Json bench;
  ASSERT_TRUE(JsonReader(ReadText(Path("bench.json"))).Parse(&bench))
      << ReadText(Path("bench.json"));
  const Json& summary = bench["summary"];
  EXPECT_EQ(summary["objects"].number, 6);
  EXPECT_EQ(summary["correct"].number + summary["missed"].number, 6);
  EXPECT_GE(summary["correct"].number, 3) << r.output;
  EXPECT_GE(summary["false_alarms"].number, 0);
  EXPECT_EQ(bench["scenes"].size(), 2u);
  EXPECT_EQ(bench["visibility"].size(), 3u);
  // Each figure in its own field: errors of millimetres, times with the worst above the median.
  EXPECT_LT(summary["feature_median_t_err_mm"].number, 5.0);
  EXPECT_LT(summary["feature_median_r_err_deg"].number, 5.0);
  EXPECT_GE(summary["worst_ms"].number, summary["median_ms"].number);
  // Every scene lists its misses (with their causes), its correct objects and its false alarms;
  // together they add up, and each reported object carries the evidence it was accepted on.
  double listed_misses = 0;
  for (const Json& scene : bench["scenes"].items) {
    ASSERT_EQ(scene["missed"].type, Json::kArray);
    ASSERT_EQ(scene["found"].type, Json::kArray);
    ASSERT_EQ(scene["false"].type, Json::kArray);
    EXPECT_EQ(double(scene["found"].size()), scene["correct"].number);
    EXPECT_EQ(double(scene["false"].size()), scene["false_alarms"].number);
    EXPECT_EQ(double(scene["found"].size() + scene["missed"].size()), scene["objects"].number);
    for (const Json& o : scene["found"].items) {
      EXPECT_FALSE(o["model"].text.empty());
      ASSERT_EQ(o["verify"].size(), 2u);
      ASSERT_EQ(o["matched"].size(), 2u);
      EXPECT_GE(o["fit_rms_mm"].number, 0.0);
    }
    // What the one-image rescue found and added (on by default).
    ASSERT_EQ(scene["rescue"].type, Json::kObject);
    EXPECT_LE(scene["rescue"]["added"].number, scene["rescue"]["found"].number);
    listed_misses += double(scene["missed"].size());
    for (const Json& miss : scene["missed"].items) {
      EXPECT_FALSE(miss["cause"].text.empty());
      EXPECT_GE(miss["visible"].number, 0.0);
      // The feature chain narrows: visible, found in both images, lost by stereo, near epipolar.
      ASSERT_EQ(miss["edges"].size(), 4u);
      ASSERT_EQ(miss["corners"].size(), 4u);
      EXPECT_LE(miss["edges_2d_both"].number, miss["edges"].items[0].number);
      EXPECT_LE(miss["edges_lost_stereo"].number, miss["edges_2d_both"].number);
      EXPECT_LE(miss["edges_lost_epipolar"].number, miss["edges_lost_stereo"].number);
    }
  }
  EXPECT_EQ(listed_misses, summary["missed"].number);

  // With the set's table file it is used and named; --no-table ignores it.
  WriteText(set + "/table.yaml", ReadText(set + "/scene00/table.yaml"));
  const ToolRun t = RunTool("bench recorded " + set);
  ASSERT_EQ(t.exit_code, 0) << t.output;
  EXPECT_NE(t.output.find("table: " + set + "/table.yaml"), std::string::npos) << t.output;
  const ToolRun nt = RunTool("bench recorded " + set + " --no-table");
  EXPECT_NE(nt.output.find("table: none"), std::string::npos) << nt.output;

  // The monocular mode on the left images with the set's table, and both systems side by side.
  const ToolRun mono =
      RunTool("bench recorded " + set + " --monocular left --json " + Path("mono_bench.json"));
  ASSERT_EQ(mono.exit_code, 0) << mono.output;
  Json mono_bench;
  ASSERT_TRUE(JsonReader(ReadText(Path("mono_bench.json"))).Parse(&mono_bench));
  EXPECT_EQ(mono_bench["mode"].text, "monocular");
  EXPECT_EQ(mono_bench["summary"]["objects"].number, 6);
  EXPECT_GE(mono_bench["summary"]["correct"].number, 3) << mono.output;
  // Its misses are listed with their causes, and what their true poses show in the image: as
  // the run found them, and with a vote threshold at the normalised vote's maximum (2), which
  // leaves the objects unfound, so that the listing is checked whatever the recogniser finds.
  auto check_listed_misses = [](const Json& bench) {
    double listed = 0;
    for (const Json& scene : bench["scenes"].items) {
      EXPECT_EQ(scene["missed"].type, Json::kArray);
      listed += double(scene["missed"].size());
      for (const Json& miss : scene["missed"].items) {
        const std::string& cause = miss["cause"].text;
        EXPECT_TRUE(cause == "no_features" || cause == "no_edges" || cause == "not_searched")
            << cause;
        EXPECT_EQ(miss["corners"].size(), 2u);
        EXPECT_EQ(miss["edge_pieces"].size(), 2u);
        if (miss["corners"].size() != 2u) continue;
        EXPECT_LE(miss["corners"].items[0].number, miss["corners"].items[1].number);
        EXPECT_LE(miss["finding_bases"].number, miss["own_bases"].number);
      }
    }
    EXPECT_EQ(listed, bench["summary"]["missed"].number);
  };
  check_listed_misses(mono_bench);
  const ToolRun unfound =
      RunTool("bench recorded " + set + " --monocular left --set mono.vote_threshold=2 --json " +
              Path("mono_unfound.json"));
  ASSERT_EQ(unfound.exit_code, 0) << unfound.output;
  Json unfound_bench;
  ASSERT_TRUE(JsonReader(ReadText(Path("mono_unfound.json"))).Parse(&unfound_bench));
  EXPECT_GT(unfound_bench["summary"]["missed"].number, 0) << unfound.output;
  check_listed_misses(unfound_bench);
  const ToolRun both = RunTool("bench recorded " + set + " --compare");
  ASSERT_EQ(both.exit_code, 0) << both.output;
  EXPECT_NE(both.output.find("side by side"), std::string::npos) << both.output;
  EXPECT_EQ(RunTool("bench recorded " + set + " --monocular middle").exit_code, 2);

  // Errors: a folder without scenes, an unknown option, a bad recognition option.
  const ToolRun empty = RunTool("bench recorded " + Path("no_such_dir"));
  EXPECT_EQ(empty.exit_code, 1) << empty.output;
  EXPECT_NE(empty.output.find("no_such_dir"), std::string::npos) << empty.output;
  EXPECT_EQ(RunTool("bench recorded " + set + " --frobnicate 1").exit_code, 2);
  EXPECT_EQ(RunTool("bench recorded " + set + " --background purple").exit_code, 2);

  // --set: a setting takes effect (no vote reaches the highest threshold; the one-image rescue,
  // which would find objects from the left image, off); an unknown name or a value of the wrong
  // kind is refused naming it, before any scene runs.
  const ToolRun strict = RunTool("bench recorded " + set +
                                 " --set recognizer.vote_threshold=2 --set rescue.enabled=0 "
                                 "--json " +
                                 Path("strict.json"));
  ASSERT_EQ(strict.exit_code, 0) << strict.output;
  Json strict_bench;
  ASSERT_TRUE(JsonReader(ReadText(Path("strict.json"))).Parse(&strict_bench));
  EXPECT_EQ(strict_bench["summary"]["correct"].number, 0) << strict.output;
  // The stereo gates: no line pair shares a kilometre of support, and rays that must meet within
  // a nanometre leave fewer corner pairs than the default 5 mm.
  const ToolRun gated = RunTool("bench recorded " + set +
                                " --set stereo.min_overlap_mm=1e6 --set stereo.max_ray_gap_mm=1e-6 "
                                "--set rescue.enabled=0 --json " +
                                Path("gated.json"));
  ASSERT_EQ(gated.exit_code, 0) << gated.output;
  const ToolRun open =
      RunTool("bench recorded " + set + " --set rescue.enabled=0 --json " + Path("open.json"));
  ASSERT_EQ(open.exit_code, 0) << open.output;
  Json gated_bench, open_bench;
  ASSERT_TRUE(JsonReader(ReadText(Path("gated.json"))).Parse(&gated_bench));
  ASSERT_TRUE(JsonReader(ReadText(Path("open.json"))).Parse(&open_bench));
  ASSERT_GT(open_bench["scenes"].size(), 0u);
  ASSERT_EQ(gated_bench["scenes"].size(), open_bench["scenes"].size());
  for (size_t i = 0; i < gated_bench["scenes"].size(); ++i) {
    const Json& g = gated_bench["scenes"][i];
    const Json& o = open_bench["scenes"][i];
    EXPECT_EQ(g["lines3d"].number, 0) << i;
    EXPECT_GT(o["lines3d"].number, 0) << i;
    EXPECT_LT(g["points3d"].number, o["points3d"].number) << i;
  }
  const ToolRun unknown = RunTool("bench recorded " + set + " --set verify.frobnicate=1");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("unknown setting verify.frobnicate"), std::string::npos)
      << unknown.output;
  for (const char* bad :
       {"verify.min_fraction=abc", "verify.min_fraction=nan", "verify.min_samples=2.5",
        "verify.min_samples=-3", "features.adaptive=2", "verify.min_fraction"}) {
    const ToolRun r = RunTool("bench recorded " + set + " --set " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    const std::string name(bad, std::strcspn(bad, "="));
    EXPECT_NE(r.output.find("setting " + name), std::string::npos) << bad << ": " << r.output;
  }
  // The monocular recogniser's settings are checked alike.
  const ToolRun mono_bad =
      RunTool("bench recorded " + set + " --monocular left --set mono.competing_bases=abc");
  EXPECT_EQ(mono_bad.exit_code, 2);
  EXPECT_NE(mono_bad.output.find("setting mono.competing_bases"), std::string::npos)
      << mono_bad.output;
  const ToolRun help = RunTool("bench recorded --help");
  EXPECT_NE(help.output.find("table_carry.tolerance_deg"), std::string::npos) << help.output;
  EXPECT_NE(help.output.find("mono.displace_weaker"), std::string::npos) << help.output;

  // One camera without the table plane is refused, saying why, rather than guessing depths.
  const ToolRun no_plane = RunTool("bench recorded " + set + " --monocular left --no-table");
  EXPECT_EQ(no_plane.exit_code, 2) << no_plane.output;
  EXPECT_NE(no_plane.output.find("without the table plane"), std::string::npos) << no_plane.output;
}

// `bench recorded --noise`: one run per level over images degraded reproducibly, the recall
// table printed and each level in the JSON; bad levels and degradations are refused.
TEST_F(RecognizeToolTest, BenchRecordedDegradesTheImagesPerNoiseLevel) {
  const std::string set = Path("noisy_set");
  ASSERT_EQ(mkdir(set.c_str(), 0777), 0);
  ASSERT_EQ(
      RunTool("render --out " + set + "/scene00 --seed 21 --objects 3 --occlusion none").exit_code,
      0);
  WriteText(set + "/calib.yaml", ReadText(set + "/scene00/calib.yaml"));
  WriteText(set + "/table.yaml", ReadText(set + "/scene00/table.yaml"));
  auto run = [&](const std::string& json) {
    return RunTool("bench recorded " + set + " --noise 0,12 --gain 0.9 --json " + json);
  };
  const ToolRun r = run(Path("noise_a.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("recall against noise"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("noise sigma 12.0 grey levels"), std::string::npos) << r.output;
  Json a, b;
  ASSERT_TRUE(JsonReader(ReadText(Path("noise_a.json"))).Parse(&a));
  const Json& levels = a["noise_levels"];
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0]["noise_sigma"].number, 0.0);
  EXPECT_EQ(levels[1]["noise_sigma"].number, 12.0);
  EXPECT_EQ(a["degradation"]["gain"].number, 0.9);
  for (const Json& level : levels.items) EXPECT_EQ(level["objects"].number, 3);
  // The full figures are the first level's.
  EXPECT_EQ(levels[0]["correct"].number, a["summary"]["correct"].number);
  // Reproducible: the same noise again gives the same figures.
  ASSERT_EQ(run(Path("noise_b.json")).exit_code, 0);
  ASSERT_TRUE(JsonReader(ReadText(Path("noise_b.json"))).Parse(&b));
  EXPECT_EQ(b["noise_levels"][1]["correct"].number, levels[1]["correct"].number);
  EXPECT_EQ(b["noise_levels"][1]["false_alarms"].number, levels[1]["false_alarms"].number);
  for (const char* bad : {"--noise -1", "--noise 3,,4", "--noise 3,", "--noise abc", "--noise 99",
                          "--blur 20", "--blur x", "--gain 0", "--noise 0,3 --carry-table"}) {
    const ToolRun refused = RunTool("bench recorded " + set + " " + bad);
    EXPECT_EQ(refused.exit_code, 2) << bad << ": " << refused.output;
  }
}

TEST_F(RecognizeToolTest, ReadsARecordedPairWithTheSetsCalibrationAndTable) {
  // Recorded-scenes layout: calib.yaml and table.yaml beside the scene folder.
  const std::string set = Path("set");
  ASSERT_EQ(std::system(("mkdir -p " + set + "/scene1 && cp " + Path("left.png") + " " +
                         Path("right.png") + " " + set + "/scene1/ && cp " + Path("calib.yaml") +
                         " " + Path("table.yaml") + " " + set + "/")
                            .c_str()),
            0);
  ToolRun r = RunTool("recognize --scene " + set + "/scene1 --json " + Path("scene.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool(Inputs(Path("calib.yaml"), Path("left.png"), Path("right.png")) + " --table " +
              Path("table.yaml") + " --json " + Path("pair.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Json scene, pair;
  ASSERT_TRUE(JsonReader(ReadText(Path("scene.json"))).Parse(&scene));
  ASSERT_TRUE(JsonReader(ReadText(Path("pair.json"))).Parse(&pair));
  EXPECT_EQ(scene["frame"].text, "camera");
  ASSERT_EQ(scene["objects"].size(), pair["objects"].size());
  ASSERT_GT(scene["objects"].size(), 0u);
  for (size_t i = 0; i < scene["objects"].size(); ++i) {
    EXPECT_EQ(scene["objects"][i]["model"].text, pair["objects"][i]["model"].text);
    EXPECT_EQ(PoseOf(scene["objects"][i]).t_mm, PoseOf(pair["objects"][i]).t_mm);
  }
  // Without a calib.yaml beside it the calibration must be given.
  ASSERT_EQ(std::system(("rm " + set + "/calib.yaml").c_str()), 0);
  r = RunTool("recognize --scene " + set + "/scene1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no calib.yaml beside"), std::string::npos) << r.output;
  // ... and then is used.
  r = RunTool("recognize --scene " + set + "/scene1 --calib " + Path("calib.yaml") + " --json " +
              Path("scene_calib.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Json given;
  ASSERT_TRUE(JsonReader(ReadText(Path("scene_calib.json"))).Parse(&given));
  EXPECT_EQ(given["objects"].size(), scene["objects"].size());
  r = RunTool("recognize --scene " + set + "/missing");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("has neither left nor right"), std::string::npos) << r.output;
  r = RunTool("recognize --scene " + set + "/scene1 --left " + Path("left.png"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST_F(RecognizeToolTest, AFolderRecordedOnOneCameraIsRecognisedFromThatImage) {
  // The firmware records only the camera in use while on one camera.
  const std::string set = Path("mono_set");
  ASSERT_EQ(std::system(("mkdir -p " + set + "/00000000 && cp " + Path("right.png") + " " + set +
                         "/00000000/ && cp " + Path("calib.yaml") + " " + Path("table.yaml") + " " +
                         set + "/")
                            .c_str()),
            0);
  ToolRun r = RunTool("recognize --scene " + set + "/00000000 --json " + Path("mono_scene.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = RunTool("recognize --calib " + Path("calib.yaml") + " --right " + Path("right.png") +
              " --table " + Path("table.yaml") + " --json " + Path("mono_right.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ExpectSameObjects(Path("mono_right.json"), Path("mono_scene.json"));
}

}  // namespace
}  // namespace sh
