#include "recog/camera/camera_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/image_check.hpp"

namespace sh {
namespace {

// The lens of OpenCV's sample stereo pairs (strong barrel distortion, k3 > 0).
CameraIntrinsics SampleLens() {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 535.9;
  c.cx = 342.3;
  c.cy = 235.6;
  c.k1 = -0.266;
  c.k2 = -0.0386;
  c.p1 = 0.00178;
  c.p2 = -0.00028;
  c.k3 = 0.238;
  return c;
}

// A distortion that turns back inside the image is refused with both radii, the message whole
// (within Status::kMaxMessage) even for the widest numbers.
TEST(CalibrationCheck, AFoldingDistortionNamesWhereItTurnsBack) {
  CameraIntrinsics cam = SampleLens();
  cam.k1 = -0.302991;  // what three of OpenCV's sample pairs give
  cam.k2 = 0.208257;
  cam.k3 = -0.238601;
  for (double k : {0.0, -1.23457e6}) {
    if (k != 0.0) cam.k1 = cam.k2 = cam.k3 = k;
    const Status s = CheckPlausibleIntrinsics(cam, "right");
    ASSERT_FALSE(s.ok());
    const std::string m = s.message();
    EXPECT_NE(m.find("right camera: distortion k1="), std::string::npos) << m;
    EXPECT_NE(m.find("folds the image: radii turn back at "), std::string::npos) << m;
    EXPECT_NE(m.find(" px, the corners are at "), std::string::npos) << m;
    EXPECT_EQ(m.substr(m.size() - 3), " px") << m;
  }
}

TEST(CameraModel, UndistortInvertsDistortOverTheWholeImage) {
  const CameraIntrinsics cam = SampleLens();
  double worst_px = 0.0;
  for (int y = 0; y <= cam.height; y += 8) {
    for (int x = 0; x <= cam.width; x += 8) {
      const Eigen::Vector2d pixel(x, y);
      const Eigen::Vector3d ray = PixelRay(cam, pixel);
      Eigen::Vector2d back;
      ASSERT_TRUE(ProjectToPixel(cam, ray * 500.0, &back));
      worst_px = std::max(worst_px, (back - pixel).norm());
    }
  }
  EXPECT_LT(worst_px, 1e-6);
}

TEST(CameraModel, ProjectionOfRayPointsIsThePixel) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  CameraIntrinsics cam = SampleLens();
  for (int i = 0; i < 200; ++i) {
    cam.k1 = -0.3 + 0.6 * u(rng);
    cam.k2 = -0.05 + 0.1 * u(rng);
    cam.k3 = 0.0;
    const Eigen::Vector2d pixel(u(rng) * cam.width, u(rng) * cam.height);
    const Eigen::Vector3d ray = PixelRay(cam, pixel);
    EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
    Eigen::Vector2d back;
    ASSERT_TRUE(ProjectToPixel(cam, ray * (100.0 + 1000.0 * u(rng)), &back));
    EXPECT_LT((back - pixel).norm(), 1e-6) << "k1 " << cam.k1 << " k2 " << cam.k2;
  }
}

TEST(CameraModel, PointsBehindTheCameraDoNotProject) {
  const CameraIntrinsics cam = SampleLens();
  Eigen::Vector2d pixel;
  EXPECT_FALSE(ProjectToPixel(cam, Eigen::Vector3d(0, 0, -100), &pixel));
  EXPECT_FALSE(ProjectToPixel(cam, Eigen::Vector3d(10, 0, 0), &pixel));
}

TEST(CameraModel, RightCentreMapsToRightOrigin) {
  StereoCalibration calib;
  calib.right_R_left = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized()).matrix();
  calib.right_t_left_mm = Eigen::Vector3d(-120, 3, -7);
  const Eigen::Vector3d c = RightCentreInLeft(calib);
  EXPECT_LT((calib.right_R_left * c + calib.right_t_left_mm).norm(), 1e-12);
}

TEST(ImageFitsCamera, RefusesEmptyMisSizedAndShortRowImages) {
  CameraIntrinsics cam;
  cam.width = 8;
  cam.height = 6;
  std::vector<uint8_t> pixels(8 * 6);
  ConstGrayView image{pixels.data(), 8, 6, 8};
  EXPECT_TRUE(CheckImageFitsCamera(image, cam, "left").ok());

  ConstGrayView empty{nullptr, 8, 6, 8};
  EXPECT_EQ(std::string(CheckImageFitsCamera(empty, cam, "left").message()), "left image is empty");
  ConstGrayView narrow{pixels.data(), 7, 6, 8};
  EXPECT_EQ(std::string(CheckImageFitsCamera(narrow, cam, "right").message()),
            "right image is 7x6 but the calibration says 8x6");
  ConstGrayView short_rows{pixels.data(), 8, 6, 7};
  EXPECT_EQ(std::string(CheckImageFitsCamera(short_rows, cam, "left").message()),
            "left image stride 7 < width 8");
}

}  // namespace
}  // namespace sh
