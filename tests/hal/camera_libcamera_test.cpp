#include "hal/linux/libcamera_camera.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sh::hal {
namespace {

// On a machine without two cameras (CI, the build host) Start() must fail cleanly with kNotFound
// and a message naming the count; everything after that must be safe to call.
TEST(CameraLibcamera, FewerThanTwoCamerasIsAClearNotFound) {
  LibcameraStereoCamera cam(LibcameraStereoConfig{});
  const Status s = cam.Start();
  if (cam.cameras_found() >= 2) {
    (void)cam.Stop();
    GTEST_SKIP() << "this machine has " << cam.cameras_found()
                 << " cameras; the missing-camera path is not reachable here";
  }
  ASSERT_EQ(s.code(), StatusCode::kNotFound) << s.message();
  char expected[64];
  std::snprintf(expected, sizeof(expected), "libcamera found %d cameras, need 2",
                cam.cameras_found());
  EXPECT_STREQ(s.message(), expected);

  StereoFrame f;
  EXPECT_EQ(cam.Capture(&f, 10).code(), StatusCode::kFailedPrecondition);
  cam.Release();
  EXPECT_TRUE(cam.Stop().ok());
  EXPECT_EQ(cam.stats().pairs_delivered, 0u);
  // A failed Start() leaves nothing behind: trying again reports the same problem.
  const Status again = cam.Start();
  EXPECT_EQ(again.code(), StatusCode::kNotFound);
  EXPECT_STREQ(again.message(), expected);
}

// Everything below needs two real cameras; on other machines it skips with libcamera's answer.
class CameraLibcameraHardware : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* left = std::getenv("STEREOHASH_LEFT_CAMERA");
    const char* right = std::getenv("STEREOHASH_RIGHT_CAMERA");
    if (left != nullptr) config_.left_id = left;
    if (right != nullptr) config_.right_id = right;
    config_.width = 640;
    config_.height = 480;
    cam_ = std::make_unique<LibcameraStereoCamera>(config_);
    const Status s = cam_->Start();
    if (!s.ok()) GTEST_SKIP() << "needs two cameras: " << s.message();
  }
  void TearDown() override {
    if (cam_) {
      EXPECT_TRUE(cam_->Stop().ok());
    }
  }
  LibcameraStereoConfig config_;
  std::unique_ptr<LibcameraStereoCamera> cam_;
};

TEST_F(CameraLibcameraHardware, CapturesSynchronisedPairsOfTheConfiguredSize) {
  const LibcameraStreamInfo& info = cam_->stream_info();
  EXPECT_FALSE(info.pixel_format.empty());
  EXPECT_GE(info.stride, info.width);
  EXPECT_GE(info.buffers_per_camera, 2u);
  uint64_t last_pair = 0;
  for (int i = 0; i < 30; ++i) {
    StereoFrame f;
    const Status s = cam_->Capture(&f, 1000);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(f.left.width, info.width);
    EXPECT_EQ(f.right.height, info.height);
    EXPECT_LE(std::llabs(f.left_timestamp_ns - f.right_timestamp_ns), config_.pairing.tolerance_ns);
    if (i > 0) {
      EXPECT_GT(f.pair_index, last_pair);
    }
    last_pair = f.pair_index;
  }
  EXPECT_GE(cam_->stats().pairs_delivered, 30u);
}

TEST_F(CameraLibcameraHardware, ReleaseKeepsTheCamerasStreaming) {
  for (int i = 0; i < 20; ++i) {
    StereoFrame f;
    ASSERT_TRUE(cam_->Capture(&f, 1000).ok());
    cam_->Release();
  }
  EXPECT_EQ(cam_->stats().timeouts, 0u);
}

// A sensor larger than the pipeline's frames is asked for its binned size, and delivers frames
// that fit (or refuses to start, naming the size it offered).
TEST(CameraLibcameraLargeSensor, IsAskedForFramesThatFit) {
  LibcameraStereoConfig config;
  config.width = kMaxSensorWidth;
  config.height = kMaxSensorHeight;
  LibcameraStereoCamera cam(config);
  const Status s = cam.Start();
  if (s.code() == StatusCode::kNotFound) GTEST_SKIP() << "needs two cameras: " << s.message();
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_LE(cam.stream_info().width, kMaxImageWidth);
  EXPECT_LE(cam.stream_info().height, kMaxImageHeight);
  EXPECT_TRUE(cam.Stop().ok());
}

}  // namespace
}  // namespace sh::hal
