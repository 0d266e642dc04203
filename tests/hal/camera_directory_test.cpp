#include "hal/sim/directory_camera.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "hal/sim/image_files.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh::hal {
namespace {

using sh::testing::TempDir;

uint8_t Pixel(int value, int x, int y) { return static_cast<uint8_t>(value + 3 * x + 5 * y); }

void WriteFile(const std::string& path, const std::string& bytes) {
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
  std::fclose(f);
}

std::string PgmBytes(int width, int height, int value, const char* comment = nullptr) {
  std::string s = "P5\n";
  if (comment != nullptr) s += std::string("# ") + comment + "\n";
  s += std::to_string(width) + " " + std::to_string(height) + "\n255\n";
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) s.push_back(static_cast<char>(Pixel(value, x, y)));
  }
  return s;
}

void WritePgm(const std::string& path, int width, int height, int value) {
  WriteFile(path, PgmBytes(width, height, value));
}

// The value a view was written with, checked over every pixel; -1 if it does not match.
int ValueShown(const ConstGrayView& v) {
  const int value = v.at(0, 0);
  for (int y = 0; y < v.height; ++y) {
    for (int x = 0; x < v.width; ++x) {
      if (v.at(x, y) != Pixel(value, x, y)) return -1;
    }
  }
  return value;
}

// Left frame k holds value 10 * k, right frame k holds 10 * k + 1.
void WriteFlatRecording(const TempDir& dir, const std::vector<int>& keys, int w = 12, int h = 7) {
  for (int k : keys) {
    WritePgm(dir.path() + "/left_" + std::to_string(k) + ".pgm", w, h, 10 * k);
    WritePgm(dir.path() + "/right_" + std::to_string(k) + ".pgm", w, h, 10 * k + 1);
  }
}

DirectoryCameraConfig Config(const TempDir& dir, bool loop = false) {
  DirectoryCameraConfig c;
  c.directory = dir.path();
  c.loop = loop;
  return c;
}

TEST(CameraDirectory, MissingOrEmptyDirectoryIsNotFound) {
  DirectoryCameraConfig c;
  c.directory = "/nonexistent/stereohash/recording";
  DirectoryCamera missing(c);
  const Status s = missing.Start();
  EXPECT_EQ(s.code(), StatusCode::kNotFound);
  EXPECT_NE(std::strstr(s.message(), "does not exist"), nullptr) << s.message();
  TempDir dir("camera_dir");
  DirectoryCamera empty(Config(dir));
  EXPECT_EQ(empty.Start().code(), StatusCode::kNotFound);
}

TEST(CameraDirectory, FlatLayoutPlaysInNaturalOrderWithSyntheticTimestamps) {
  TempDir dir("camera_dir");
  WriteFlatRecording(dir, {10, 2, 1});
  WriteFile(dir.path() + "/notes.txt", "ignored");
  DirectoryCameraConfig c = Config(dir);
  c.frame_period_ns = 50'000'000;
  DirectoryCamera cam(c);
  ASSERT_TRUE(cam.Start().ok());
  EXPECT_EQ(cam.frame_count(), 3u);
  const int expected_keys[] = {1, 2, 10};
  for (int i = 0; i < 3; ++i) {
    StereoFrame f;
    const Status s = cam.Capture(&f, 100);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(ValueShown(f.left), 10 * expected_keys[i]);
    EXPECT_EQ(ValueShown(f.right), 10 * expected_keys[i] + 1);
    EXPECT_EQ(f.left_timestamp_ns, c.first_timestamp_ns + i * c.frame_period_ns);
    EXPECT_EQ(f.right_timestamp_ns, f.left_timestamp_ns);
  }
  StereoFrame f;
  const Status end = cam.Capture(&f, 100);
  EXPECT_EQ(end.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::strstr(end.message(), "end of recording"), nullptr) << end.message();
  EXPECT_EQ(cam.stats().errors, 0u);
}

TEST(CameraDirectory, SubfolderLayoutAndLooping) {
  TempDir dir("camera_dir");
  const std::string l = dir.Mkdir("left");
  const std::string r = dir.Mkdir("right");
  for (int k = 0; k < 2; ++k) {
    WritePgm(l + "/frame" + std::to_string(k) + ".pgm", 5, 4, 10 * k);
    WritePgm(r + "/frame" + std::to_string(k) + ".pgm", 5, 4, 10 * k + 1);
  }
  DirectoryCamera cam(Config(dir, /*loop=*/true));
  ASSERT_TRUE(cam.Start().ok());
  int64_t last_t = -1;
  for (int i = 0; i < 5; ++i) {
    StereoFrame f;
    ASSERT_TRUE(cam.Capture(&f, 100).ok());
    EXPECT_EQ(ValueShown(f.left), 10 * (i % 2));
    EXPECT_EQ(ValueShown(f.right), 10 * (i % 2) + 1);
    EXPECT_GT(f.left_timestamp_ns, last_t) << "timestamps keep growing across loops";
    last_t = f.left_timestamp_ns;
  }
}

TEST(CameraDirectory, SceneFolderLayoutOfRecordedSetsPlaysInNaturalOrder) {
  // The recorded-scenes format: calib.yaml beside scene folders holding left/right and truth.
  TempDir dir("camera_dir");
  WriteFile(dir.path() + "/calib.yaml", "%YAML:1.0\n");
  for (int k : {10, 2, 1}) {
    const std::string scene = dir.Mkdir("scene" + std::to_string(k));
    WritePgm(scene + "/left.pgm", 6, 5, 10 * k);
    WritePgm(scene + "/right.pgm", 6, 5, 10 * k + 1);
    WriteFile(scene + "/truth.json", "{}");
  }
  dir.Mkdir("empty_folder");
  DirectoryCamera cam(Config(dir, /*loop=*/true));
  ASSERT_TRUE(cam.Start().ok());
  EXPECT_EQ(cam.frame_count(), 3u);
  const int order[] = {1, 2, 10, 1};
  for (int k : order) {
    StereoFrame f;
    ASSERT_TRUE(cam.Capture(&f, 100).ok());
    EXPECT_EQ(ValueShown(f.left), 10 * k);
    EXPECT_EQ(ValueShown(f.right), 10 * k + 1);
  }
}

TEST(CameraDirectory, SceneFolderWithoutRightImageIsNamed) {
  TempDir dir("camera_dir");
  const std::string a = dir.Mkdir("scene1");
  WritePgm(a + "/left.pgm", 6, 5, 0);
  WritePgm(a + "/right.pgm", 6, 5, 1);
  const std::string b = dir.Mkdir("scene2");
  WritePgm(b + "/left.pgm", 6, 5, 0);
  DirectoryCamera cam(Config(dir));
  const Status s = cam.Start();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "scene2/left.pgm has no right partner"), nullptr)
      << s.message();
}

TEST(CameraDirectory, PlaysPngRecordings) {
  TempDir dir("camera_dir");
  const std::string l = dir.Mkdir("left");
  const std::string r = dir.Mkdir("right");
  std::vector<uint8_t> pixels(size_t{9} * 5);
  for (int k = 0; k < 3; ++k) {
    for (int side = 0; side < 2; ++side) {
      for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 9; ++x) pixels[(size_t{9} * y) + x] = Pixel(10 * k + side, x, y);
      }
      const std::string path = (side == 0 ? l : r) + "/" + std::to_string(k) + ".png";
      ASSERT_TRUE(WritePng(path.c_str(), ConstGrayView{pixels.data(), 9, 5, 9}).ok());
    }
  }
  DirectoryCamera cam(Config(dir));
  ASSERT_TRUE(cam.Start().ok());
  for (int k = 0; k < 3; ++k) {
    StereoFrame f;
    const Status s = cam.Capture(&f, 100);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(f.left.width, 9);
    EXPECT_EQ(ValueShown(f.left), 10 * k);
    EXPECT_EQ(ValueShown(f.right), 10 * k + 1);
  }
}

TEST(CameraDirectory, MissingPartnerFailsStartNamingTheFile) {
  TempDir dir("camera_dir");
  WriteFlatRecording(dir, {1, 2});
  WritePgm(dir.path() + "/left_3.pgm", 12, 7, 0);
  DirectoryCamera cam(Config(dir));
  const Status s = cam.Start();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "left_3.pgm has no right partner"), nullptr) << s.message();
}

TEST(CameraDirectory, DifferentLeftRightSizesAreAnError) {
  TempDir dir("camera_dir");
  WritePgm(dir.path() + "/left_1.pgm", 12, 7, 0);
  WritePgm(dir.path() + "/right_1.pgm", 6, 7, 0);
  DirectoryCamera cam(Config(dir));
  const Status s = cam.Start();
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "left and right must match"), nullptr) << s.message();
}

TEST(CameraDirectory, BadFramesMidRecordingAreReportedCountedAndSkipped) {
  TempDir dir("camera_dir");
  WriteFlatRecording(dir, {1, 2, 3, 4, 5});
  // Frame 2: pixels cut short. Frame 3: garbage header. Frame 4: sizes differ left/right.
  const std::string full = PgmBytes(12, 7, 20);
  WriteFile(dir.path() + "/left_2.pgm", full.substr(0, full.size() - 10));
  WriteFile(dir.path() + "/right_3.pgm", "JUNK");
  WritePgm(dir.path() + "/right_4.pgm", 6, 7, 41);
  DirectoryCamera cam(Config(dir));
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(ValueShown(f.left), 10);

  Status s = cam.Capture(&f, 100);
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_NE(std::strstr(s.message(), "left left_2.pgm"), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "truncated"), nullptr) << s.message();

  s = cam.Capture(&f, 100);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "right_3.pgm"), nullptr) << s.message();

  s = cam.Capture(&f, 100);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "left and right must match"), nullptr) << s.message();

  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  EXPECT_EQ(ValueShown(f.left), 50);
  EXPECT_EQ(cam.stats().errors, 3u);
  EXPECT_EQ(cam.Capture(&f, 100).code(), StatusCode::kOutOfRange);
}

// A frame of another size than the first pair is refused by name and counted, and playback goes
// on. The decode buffers hold the first pair's pixels (not the 1280 x 1024 maximum): a larger
// frame is refused before decoding, naming both sizes.
TEST(CameraDirectory, FrameWithDifferentSizeThanRecordingIsAnError) {
  TempDir dir("camera_dir");
  WriteFlatRecording(dir, {1, 4});
  WritePgm(dir.path() + "/left_2.pgm", 8, 8, 20);
  WritePgm(dir.path() + "/right_2.pgm", 8, 8, 21);
  WritePgm(dir.path() + "/left_3.pgm", 16, 9, 30);
  WritePgm(dir.path() + "/right_3.pgm", 16, 9, 31);
  DirectoryCamera cam(Config(dir));
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  ASSERT_TRUE(cam.Capture(&f, 100).ok());
  Status s = cam.Capture(&f, 100);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(), "expected 12x7"), nullptr) << s.message();
  s = cam.Capture(&f, 100);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(s.message(),
                        "left left_3.pgm is 16x9, larger than the recording's first pair (12x7)"),
            nullptr)
      << s.message();
  s = cam.Capture(&f, 100);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(ValueShown(f.left), 40);
  EXPECT_EQ(cam.stats().errors, 2u);
}

// Frames are decoded straight into the camera's buffers, rows packed, then moved to the
// buffer's stride: a view with a wider stride shows the same pixels as a packed one.
// A 5 MP recording (larger than a pipeline frame) plays binned 2 x 2 into 1296 x 1024 frames,
// each pixel the rounded mean of its block, as a binning sensor would deliver it.
TEST(CameraDirectory, ImagesLargerThanAFrameAreBinnedToFit) {
  TempDir dir("camera_dir_5mp");
  const int w = kMaxSensorWidth, h = kMaxSensorHeight;
  std::vector<uint8_t> full(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) full[static_cast<size_t>(y) * w + x] = Pixel(0, x * 7, y * 3);
  }
  for (const char* side : {"left_0.pgm", "right_0.pgm"}) {
    ASSERT_TRUE(hal::WritePgm((dir.path() + "/" + side).c_str(), {full.data(), w, h, w}).ok());
  }
  DirectoryCamera cam(Config(dir));
  ASSERT_TRUE(cam.Start().ok());
  StereoFrame f;
  const Status s = cam.Capture(&f, 100);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(f.left.width, w / 2);
  ASSERT_EQ(f.left.height, h / 2);
  for (const ConstGrayView& v : {ConstGrayView(f.left), ConstGrayView(f.right)}) {
    for (int y = 0; y < v.height; y += 37) {
      for (int x = 0; x < v.width; x += 41) {
        const uint8_t* r0 = &full[(static_cast<size_t>(y) * w + x) * 2];
        const int sum = r0[0] + r0[1] + r0[w] + r0[w + 1];
        ASSERT_EQ(v.at(x, y), (sum + 2) / 4) << x << "," << y;
      }
    }
  }
}

// Beyond the largest sensor a recording is refused by name, not cropped.
TEST(CameraDirectory, ImagesLargerThanTheLargestSensorAreRefused) {
  TempDir dir("camera_dir_huge");
  WriteFlatRecording(dir, {0}, kMaxSensorWidth + 2, 8);
  DirectoryCamera cam(Config(dir));
  const Status s = cam.Start();
  EXPECT_EQ(s.code(), StatusCode::kOutOfRange);
  EXPECT_NE(std::strstr(s.message(), "2594"), nullptr) << s.message();
}

TEST(CameraDirectory, RendersIntoViewsOfAWiderStride) {
  TempDir dir("camera_dir");
  WriteFlatRecording(dir, {1, 2}, 13, 9);
  DirectoryFrameSource source(dir.path(), /*loop=*/false);
  int w = 0;
  int h = 0;
  ASSERT_TRUE(source.Open(&w, &h).ok());
  ASSERT_EQ(w, 13);
  ASSERT_EQ(h, 9);
  for (const int stride : {13, 14, 40}) {
    std::vector<uint8_t> left(static_cast<size_t>(stride) * h, 0xEE);
    std::vector<uint8_t> right(static_cast<size_t>(stride) * h, 0xEE);
    const GrayView lv{left.data(), w, h, stride};
    const GrayView rv{right.data(), w, h, stride};
    ASSERT_TRUE(source.Render(1, lv, rv).ok()) << "stride " << stride;
    EXPECT_EQ(ValueShown(lv), 20) << "stride " << stride;
    EXPECT_EQ(ValueShown(rv), 21) << "stride " << stride;
  }
  // A view of another size is refused, not written past.
  std::vector<uint8_t> small(static_cast<size_t>(w) * (h - 1));
  const GrayView sv{small.data(), w, h - 1, w};
  EXPECT_EQ(source.Render(0, sv, sv).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh::hal
