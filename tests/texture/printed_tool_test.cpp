// End to end through the `stereohash` program for printed cartons: `tables build` learns the
// feature database of models/textured, `bench textured --rendered --save` renders scenes with
// their truth, `recognize` finds the cartons at their poses from the files alone; damaged or
// mixed input is refused with a message.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "recog/geometry/rigid_transform.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/support/tool_run.hpp"
#include "tools/eval/mini_json.hpp"

namespace sh {
namespace {

using testing::ToolRun;

ToolRun RunTool(const std::string& args) { return testing::RunTool(STEREOHASH_EXE, args); }

std::string ReadText(const std::string& path) { return testing::ReadFileText(path); }

Json ReadJson(const std::string& path) {
  Json j;
  EXPECT_TRUE(JsonReader(ReadText(path)).Parse(&j)) << path;
  return j;
}

RigidTransform PoseOf(const Json& o) {
  RigidTransform T;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.R(r, c) = static_cast<float>(o["R"][r][c].number);
    T.t_mm(r) = static_cast<float>(o["t"][r].number);
  }
  return T;
}

class PrintedTool : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    temp_ = new sh::testing::TempDir("printed");
    ASSERT_TRUE(temp_->ok());
    dir_ = temp_->path();
  }
  static void TearDownTestSuite() { delete temp_; }
  static sh::testing::TempDir* temp_;
  static std::string dir_;
};
sh::testing::TempDir* PrintedTool::temp_ = nullptr;
std::string PrintedTool::dir_;

TEST_F(PrintedTool, BuildsRendersAndRecognisesCartons) {
  const std::string db = dir_ + "/cartons.bin";
  ToolRun build = RunTool("tables build --models models/textured --out " + db);
  ASSERT_EQ(build.exit_code, 0) << build.output;
  EXPECT_NE(build.output.find("4 printed models, 24 faces"), std::string::npos) << build.output;
  ToolRun info = RunTool("tables info " + db);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("model 1 pills"), std::string::npos) << info.output;

  // One scene per row of the grid, saved as recorded pairs; the bench scores them too.
  const std::string scenes = dir_ + "/scenes";
  ToolRun bench = RunTool("bench textured --rendered 1 --seed 77 --no-peer --save " + scenes +
                          " --json " + dir_ + "/bench.json");
  ASSERT_EQ(bench.exit_code, 0) << bench.output;
  const Json b = ReadJson(dir_ + "/bench.json");
  EXPECT_EQ(b["texture"]["correct"].number, b["texture"]["objects"].number) << bench.output;
  EXPECT_EQ(b["texture"]["false_alarms"].number, 0) << bench.output;

  // `recognize` on one saved pair, from the files alone.
  const std::string scene = scenes + "/seed79";
  const std::string out = dir_ + "/poses.json";
  ToolRun rec = RunTool("recognize --calib " + scene + "/calib.yaml --left " + scene +
                        "/left.png --right " + scene + "/right.png --tables " + db + " --json " +
                        out + " --overlay " + dir_ + "/overlay.png --threads 2");
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  const Json truth = ReadJson(scene + "/truth.json");
  const Json found = ReadJson(out);
  EXPECT_EQ(found["frame"].text, "camera");
  EXPECT_EQ(found["threads"].number, 2);
  ASSERT_EQ(found["objects"].size(), truth["objects"].size()) << rec.output;
  for (const Json& t : truth["objects"].items) {
    bool ok = false;
    for (const Json& f : found["objects"].items) {
      if (f["model"].text != t["model"].text) continue;
      const RigidTransform a = PoseOf(f), e = PoseOf(t);
      ok |= (a.t_mm - e.t_mm).norm() < 2.0f && RotationAngleDeg(a.R.transpose() * e.R) < 2.0f;
    }
    EXPECT_TRUE(ok) << t["model"].text << "\n" << rec.output;
  }
  struct stat st {};
  EXPECT_EQ(stat((dir_ + "/overlay.png").c_str(), &st), 0);
  EXPECT_GT(st.st_size, 1000);
}

TEST_F(PrintedTool, RefusesDamagedModelSetsAndBuildsMixedFolders) {
  // A database with a flipped byte: the CRC names the damage.
  const std::string db = dir_ + "/small.bin";
  ASSERT_EQ(RunTool("tables build --models models/textured --out " + db).exit_code, 0);
  std::string bytes = ReadText(db);
  bytes[bytes.size() / 2] ^= 0x20;
  std::ofstream(db, std::ios::binary) << bytes;
  ToolRun info = RunTool("tables info " + db);
  EXPECT_EQ(info.exit_code, 1);
  EXPECT_NE(info.output.find("model set corrupt"), std::string::npos) << info.output;
  // A folder with printed and plain models: one model set with a section of each kind.
  const std::string mixed = dir_ + "/mixed";
  ASSERT_EQ(mkdir(mixed.c_str(), 0777), 0);
  for (const char* f :
       {"textured/pills.obj", "textured/pills.mtl", "textured/pills.png", "cube.obj"}) {
    const std::string name = std::string(f).substr(std::string(f).find_last_of('/') + 1);
    std::ofstream(std::string(mixed).append("/").append(name), std::ios::binary)
        << ReadText(std::string("models/") + f);
  }
  ToolRun build = RunTool("tables build --models " + mixed + " --out " + dir_ + "/m.bin");
  ASSERT_EQ(build.exit_code, 0) << build.output;
  EXPECT_NE(build.output.find("model set, "), std::string::npos) << build.output;
  ToolRun mixed_info = RunTool("tables info " + dir_ + "/m.bin");
  ASSERT_EQ(mixed_info.exit_code, 0) << mixed_info.output;
  EXPECT_NE(mixed_info.output.find("section 0: HASH3D"), std::string::npos) << mixed_info.output;
  EXPECT_NE(mixed_info.output.find("section 1: TEXTURE_FEATURES"), std::string::npos)
      << mixed_info.output;
  EXPECT_NE(mixed_info.output.find("model 0 cube"), std::string::npos) << mixed_info.output;
  EXPECT_NE(mixed_info.output.find("model 0 pills"), std::string::npos) << mixed_info.output;
}

}  // namespace
}  // namespace sh
