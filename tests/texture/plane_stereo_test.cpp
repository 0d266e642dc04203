// Plane stereo on a rendered stereo pair of a printed plane (distorted, rotated cameras): the
// Shi-Tomasi points of the face's contour find their right-image correspondences by ZNCC along
// the epipolar curve, and the triangulated points lie on the plane.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/texture/feature_extractor.hpp"
#include "recog/texture/plane_stereo.hpp"
#include "tests/support/print_images.hpp"

namespace sh::texture {
namespace {

struct PlaneScene {
  StereoCalibration calib;
  RigidTransform cam_T_face;  // face frame: the pattern's (x, y) in millimetres, z = 0
  testing::PrintPattern pattern{80.0f, 70, 21};
};

// The face tilted by tilt_rad (0.8: 45 degrees), its centre 400 mm ahead.
PlaneScene MakeScene(float tilt_rad = 0.8f) {
  PlaneScene s;
  s.calib = testing::RotatedStereoRig(400, 320, 900);
  s.cam_T_face.R = (Eigen::AngleAxisf(3.14159265f, Eigen::Vector3f::UnitX()) *
                    Eigen::AngleAxisf(-tilt_rad, Eigen::Vector3f(1, 0.3f, 0).normalized()))
                       .toRotationMatrix();
  s.cam_T_face.t_mm = Eigen::Vector3f(0, 0, 400) - s.cam_T_face.R * Eigen::Vector3f(40, 40, 0);
  return s;
}

Plane3 FacePlane(const RigidTransform& cam_T_face) {
  Plane3 p;
  p.normal = cam_T_face.R.col(2).cast<double>();
  p.d_mm = p.normal.dot(cam_T_face.t_mm.cast<double>());
  return p;
}

testing::TestImage Render(const PlaneScene& s, int camera) {
  const CameraIntrinsics& cam = camera == 0 ? s.calib.left : s.calib.right;
  // Face pose in this camera.
  RigidTransform T = s.cam_T_face;
  if (camera == 1) {
    T.R = s.calib.right_R_left.cast<float>() * T.R;
    T.t_mm = s.calib.right_R_left.cast<float>() * s.cam_T_face.t_mm +
             s.calib.right_t_left_mm.cast<float>();
  }
  const Plane3 plane = FacePlane(T);
  const RigidTransform face_T_cam = T.Inverse();
  return testing::RenderPattern(
      s.pattern, cam.width, cam.height,
      [&](float x, float y, Eigen::Vector2f* q) {
        Eigen::Vector3d hit;
        if (!IntersectRayPlane(PixelRay(cam, {x, y}), plane, &hit)) return false;
        const Eigen::Vector3f f = face_T_cam * hit.cast<float>();
        *q = f.head<2>();
        return true;
      },
      0.25f);
}

// The Shi-Tomasi points of the face's contour (projected) in the rendered left image.
void SelectFacePoints(const PlaneScene& s, const testing::TestImage& left,
                      const PlaneStereoConfig& config, Vector<Eigen::Vector2f>& points) {
  auto ex = std::make_unique<TextureFeatureExtractor>();
  auto features = std::make_unique<TextureFeatures>();
  ASSERT_TRUE(ex->Extract(left.view(), TextureFeatureConfig{}, features.get()).ok());
  Eigen::Vector2f contour[4];
  const float corners[4][2] = {{0, 0}, {80, 0}, {80, 80}, {0, 80}};
  for (int k = 0; k < 4; ++k) {
    Eigen::Vector2d px;
    ASSERT_TRUE(ProjectToPixel(
        s.calib.left,
        (s.cam_T_face * Eigen::Vector3f(corners[k][0], corners[k][1], 0)).cast<double>(), &px));
    contour[k] = px.cast<float>();
  }
  SelectContourPoints(ex->min_eigenvalue(), contour, 4, config, points);
}

TEST(PlaneStereo, ContourPointsTriangulateOntoThePlane) {
  const PlaneScene s = MakeScene();
  const testing::TestImage left = Render(s, 0);
  const testing::TestImage right = Render(s, 1);
  PlaneStereoConfig config;
  auto points = std::make_unique<Vector<Eigen::Vector2f, kMaxFaceStereoPoints>>();
  SelectFacePoints(s, left, config, *points);
  ASSERT_GT(points->size(), 40u);
  // A provisional plane 4 % too far and tilted by 6 degrees.
  RigidTransform prior_pose = s.cam_T_face;
  prior_pose.R =
      prior_pose.R * Eigen::AngleAxisf(0.1f, Eigen::Vector3f::UnitY()).toRotationMatrix();
  prior_pose.t_mm *= 1.04f;
  const Plane3 prior = FacePlane(prior_pose);
  const Plane3 truth = FacePlane(s.cam_T_face);
  PlaneStereoMatcher matcher;
  matcher.Reset(&s.calib, left.view(), right.view());
  auto matched = std::make_unique<Vector<StereoPoint, kMaxFaceStereoPoints>>();
  for (const Eigen::Vector2f& p : *points) {
    StereoPoint sp;
    if (matcher.Match(p, prior, config, &sp)) {
      ASSERT_TRUE(matched->push_back(sp));
    }
  }
  EXPECT_GT(matched->size(), points->size() * 7 / 10);
  int close = 0;
  for (const StereoPoint& sp : *matched) {
    const double off = std::fabs(truth.normal.dot(sp.x_mm.cast<double>()) - truth.d_mm);
    close += off < 0.5 ? 1 : 0;
    // The 3-D point lies on the left ray and projects to the right pixel found.
    Eigen::Vector2d l, r;
    ASSERT_TRUE(ProjectToPixel(s.calib.left, sp.x_mm.cast<double>(), &l));
    ASSERT_TRUE(ProjectToPixel(
        s.calib.right, s.calib.right_R_left * sp.x_mm.cast<double>() + s.calib.right_t_left_mm,
        &r));
    EXPECT_LT((l - sp.left_px.cast<double>()).norm(), 1e-3);
    EXPECT_LT((r - sp.right_px.cast<double>()).norm(), 1e-3);
  }
  EXPECT_GT(close, static_cast<int>(matched->size()) * 9 / 10);
  Plane3 fitted;
  PlaneFitStats stats;
  ASSERT_TRUE(FitPlaneRansac(*matched, config, &fitted, &stats));
  EXPECT_LT(std::acos(std::min(1.0, std::fabs(fitted.normal.dot(truth.normal)))) * 57.3, 0.5);
  EXPECT_LT(stats.mean_abs_mm, 0.3);
}

// The recogniser's second pass: a face 63 degrees from facing the camera, searched with a
// provisional plane facing it (what a small face's poor homography leaves), correlates fewer
// points than with its true plane; the plane fitted to those few, taken as the prior for a
// second pass, brings the count up to within a tenth of the true plane's.
TEST(PlaneStereo, TheMeasuredPlaneAsPriorCorrelatesMorePoints) {
  const PlaneScene s = MakeScene(1.1f);
  const testing::TestImage left = Render(s, 0);
  const testing::TestImage right = Render(s, 1);
  PlaneStereoConfig config;
  auto points = std::make_unique<Vector<Eigen::Vector2f, kMaxFaceStereoPoints>>();
  SelectFacePoints(s, left, config, *points);
  ASSERT_GT(points->size(), 40u);
  PlaneStereoMatcher matcher;
  matcher.Reset(&s.calib, left.view(), right.view());
  auto matched = std::make_unique<Vector<StereoPoint, kMaxFaceStereoPoints>>();
  auto correlate = [&](const Plane3& prior) {
    matched->clear();
    for (const Eigen::Vector2f& p : *points) {
      StereoPoint sp;
      if (matcher.Match(p, prior, config, &sp)) {
        EXPECT_TRUE(matched->push_back(sp));
      }
    }
    return matched->size();
  };
  const size_t with_truth = correlate(FacePlane(s.cam_T_face));
  const Eigen::Vector3d centre = (s.cam_T_face * Eigen::Vector3f(40, 40, 0)).cast<double>();
  Plane3 facing;
  facing.normal = -centre.normalized();
  facing.d_mm = facing.normal.dot(centre);
  const size_t with_facing = correlate(facing);
  EXPECT_LT(with_facing, with_truth);
  Plane3 measured;
  PlaneFitStats stats;
  ASSERT_TRUE(FitPlaneRansac(*matched, config, &measured, &stats));
  const size_t with_measured = correlate(measured);
  EXPECT_GT(with_measured, with_facing);
  EXPECT_GE(with_measured * 10, with_truth * 9);
}

TEST(PlaneStereo, AFlatWindowHasNoMatch) {
  const PlaneScene s = MakeScene();
  testing::TestImage flat(s.calib.left.width, s.calib.left.height, 128);
  PlaneStereoMatcher matcher;
  matcher.Reset(&s.calib, flat.view(), flat.view());
  StereoPoint sp;
  EXPECT_FALSE(matcher.Match({200, 160}, FacePlane(s.cam_T_face), PlaneStereoConfig{}, &sp));
}

}  // namespace
}  // namespace sh::texture
