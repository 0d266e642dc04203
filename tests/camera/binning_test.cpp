#include "recog/camera/binning.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "recog/camera/calibration_check.hpp"

namespace sh {
namespace {

// A 5 MP machine-vision camera: 2592 x 2048, principal point off centre, barrel distortion with
// tangential terms.
StereoCalibration FiveMegapixelRig() {
  StereoCalibration c;
  c.left.width = c.right.width = 2592;
  c.left.height = c.right.height = 2048;
  c.left.fx = 2250.0, c.left.fy = 2252.3, c.left.cx = 1290.6, c.left.cy = 1031.3;
  c.left.k1 = -0.12, c.left.k2 = 0.04, c.left.p1 = 0.0004, c.left.p2 = -0.0003, c.left.k3 = 0.01;
  c.right = c.left;
  c.right.cx = 1301.2;
  c.right_t_left_mm = Eigen::Vector3d(-100.0, 0.5, 2.0);
  return c;
}

// A point seen by the full sensor at pixel u is seen in the binned image at (u + 0.5) / f - 0.5:
// the binned calibration projects every point there, distortion included.
TEST(CalibrationBinning, ProjectsWhereTheBinnedPixelsAre) {
  const StereoCalibration full = FiveMegapixelRig();
  for (int factor : {2, 3, 4}) {
    const CameraIntrinsics binned = BinIntrinsics(full.left, factor);
    EXPECT_EQ(binned.width, 2592 / factor);
    EXPECT_EQ(binned.height, 2048 / factor);
    for (double x : {-180.0, -40.0, 0.0, 75.0, 200.0}) {
      for (double y : {-150.0, 10.0, 160.0}) {
        const Eigen::Vector3d p(x, y, 400.0);
        Eigen::Vector2d u_full, u_binned;
        ASSERT_TRUE(ProjectToPixel(full.left, p, &u_full));
        ASSERT_TRUE(ProjectToPixel(binned, p, &u_binned));
        const Eigen::Vector2d expected = (u_full.array() + 0.5) / factor - 0.5;
        EXPECT_NEAR(u_binned.x(), expected.x(), 1e-9) << factor;
        EXPECT_NEAR(u_binned.y(), expected.y(), 1e-9) << factor;
        // And back: the ray through the binned pixel is the ray through the full one.
        EXPECT_LT((PixelRay(binned, u_binned) - PixelRay(full.left, u_full)).norm(), 1e-9);
      }
    }
  }
}

TEST(CalibrationBinning, FrameCalibrationBinsASensorLargerThanAFrame) {
  const StereoCalibration full = FiveMegapixelRig();
  EXPECT_TRUE(ValidateStereoCalibration(full, kSensorBounds).ok());
  EXPECT_EQ(ValidateStereoCalibration(full).code(), StatusCode::kOutOfRange);  // not a frame
  const Result<StereoCalibration> frames = FrameCalibration(full);
  ASSERT_TRUE(frames.ok()) << frames.status().message();
  EXPECT_EQ(frames->left.width, 1296);
  EXPECT_EQ(frames->right.height, 1024);
  EXPECT_DOUBLE_EQ(frames->left.fx, 1125.0);
  EXPECT_DOUBLE_EQ(frames->right.cx, (1301.2 + 0.5) / 2 - 0.5);
  EXPECT_EQ(frames->left.k1, full.left.k1);
  EXPECT_EQ(frames->right_t_left_mm, full.right_t_left_mm);
  EXPECT_TRUE(ValidateStereoCalibration(*frames).ok());
  // A calibration that fits a frame is kept as it is.
  const Result<StereoCalibration> same = FrameCalibration(*frames);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->left.width, 1296);
  EXPECT_EQ(same->left.cx, frames->left.cx);
}

TEST(CalibrationBinning, BeyondTheLargestSensorIsRefused) {
  StereoCalibration big = FiveMegapixelRig();
  big.left.width = big.right.width = 4000;
  EXPECT_EQ(ValidateStereoCalibration(big, kSensorBounds).code(), StatusCode::kOutOfRange);
  const Result<StereoCalibration> frames = FrameCalibration(big);
  ASSERT_FALSE(frames.ok());
  EXPECT_NE(std::strstr(frames.status().message(), "4000x2048"), nullptr)
      << frames.status().message();
}

}  // namespace
}  // namespace sh
