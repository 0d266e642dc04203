// Geometry of the texture path by its identities: homographies and their poses, Horn's absolute
// orientation (against Eigen's Umeyama), the RANSAC plane, the final pose refinement, and the
// occlusion test of the print verification.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "recog/texture/absolute_orientation.hpp"
#include "recog/texture/planar_fit.hpp"
#include "recog/texture/plane_stereo.hpp"
#include "recog/texture/print_verify.hpp"
#include "recog/texture/texture_pose.hpp"
#include "tests/support/print_images.hpp"

namespace sh::texture {
namespace {

RigidTransform RandomPose(std::mt19937& rng, float max_angle, const Eigen::Vector3f& t) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Eigen::Vector3f axis = Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized();
  RigidTransform T;
  T.R = Eigen::AngleAxisf(max_angle * u(rng), axis).toRotationMatrix();
  T.t_mm = t;
  return T;
}

// The homography of a face frame (a, b, 0) under cam_T_face for an ideal camera.
Eigen::Matrix3d HomographyOf(const RigidTransform& cam_T_face, double f, double cx, double cy) {
  Eigen::Matrix3d K;
  K << f, 0, cx, 0, f, cy, 0, 0, 1;
  Eigen::Matrix3d M;
  M.col(0) = cam_T_face.R.col(0).cast<double>();
  M.col(1) = cam_T_face.R.col(1).cast<double>();
  M.col(2) = cam_T_face.t_mm.cast<double>();
  const Eigen::Matrix3d H = K * M;
  return H / H(2, 2);
}

// The match of face point (a, b) where H puts it, displaced by (dx, dy) pixels.
PlanarMatch MatchOf(const Eigen::Matrix3d& H, float a, float b, float dx, float dy, int id) {
  const Eigen::Vector2d x = ApplyHomography(H, a, b);
  PlanarMatch p;
  p.a_mm = a;
  p.b_mm = b;
  p.x_px = static_cast<float>(x.x()) + dx;
  p.y_px = static_cast<float>(x.y()) + dy;
  p.keypoint = static_cast<uint16_t>(id);
  return p;
}

TEST(PlanarFit, RecoversTheHomographyAndDropsOutliers) {
  std::mt19937 rng(1);
  const RigidTransform pose = RandomPose(rng, 0.6f, {10, -20, 450});
  const Eigen::Matrix3d H = HomographyOf(pose, 1100, 380, 290);
  std::uniform_real_distribution<float> ab(-40.0f, 40.0f);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  auto m = std::make_unique<Vector<PlanarMatch, 256>>();
  for (int i = 0; i < 60; ++i) {
    const float a = ab(rng), b = ab(rng);
    const float dx = noise(rng), dy = noise(rng);
    ASSERT_TRUE(m->push_back(MatchOf(H, a, b, dx, dy, i)));
  }
  for (int i = 0; i < 8; ++i) {  // gross outliers
    PlanarMatch p = (*m)[static_cast<size_t>(i)];
    p.x_px += 40.0f + 10.0f * i;
    p.keypoint = static_cast<uint16_t>(1000 + i);
    ASSERT_TRUE(m->push_back(p));
  }
  const PlanarFit fit = FitFacePlane(*m, PlanarFitConfig{});
  ASSERT_TRUE(fit.accepted);
  EXPECT_LT(fit.mean_error_px, 0.5);
  for (const PlanarMatch& p : *m) EXPECT_LT(p.keypoint, 1000) << "outlier kept";
  EXPECT_GE(fit.matches, 50);
  // The fitted homography maps the face like the true one.
  for (float a : {-40.0f, 0.0f, 40.0f}) {
    for (float b : {-40.0f, 0.0f, 40.0f}) {
      EXPECT_LT((ApplyHomography(fit.image_H_face, a, b) - ApplyHomography(H, a, b)).norm(), 0.5);
    }
  }
}

// A small face far away (1.7 px/mm) with few matches, and as many wrong ones: one print point
// matched at four places around its own (a repeated element) and two more off by 5 and 8 px.
// The largest affine consensus keeps the right ones; the homography from them maps them.
TEST(PlanarFit, AffineConsensusDropsRepeatedElementMatches) {
  RigidTransform pose;
  pose.R =
      Eigen::AngleAxisf(0.5f, Eigen::Vector3f(0.3f, 1.0f, 0.2f).normalized()).toRotationMatrix();
  pose.t_mm = {20, -30, 440};
  const Eigen::Matrix3d H = HomographyOf(pose, 760, 512, 384);
  auto m = std::make_unique<Vector<PlanarMatch, 64>>();
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  auto add = [&](float a, float b, float dx, float dy, int id) {
    const float nx = noise(rng), ny = noise(rng);
    ASSERT_TRUE(m->push_back(MatchOf(H, a, b, dx + nx, dy + ny, id)));
  };
  const float right[9][2] = {{17, 5},  {12, 5},  {10, 5},  {5, 5},  {26, 6},
                             {13, 11}, {30, 13}, {21, 13}, {13, 12}};
  for (int i = 0; i < 9; ++i) add(right[i][0], right[i][1], 0, 0, i);
  add(18, 5, -12, 9, 100);  // the repeated element
  add(18, 5, 11, -10, 101);
  add(18, 5, 5, -5, 102);
  add(18, 5, 9, -12, 103);
  add(14, 13, -4, 3, 104);
  add(17, 13, 6, 5, 105);

  ASSERT_TRUE(KeepAffineConsensus(*m, PlanarFitConfig{}));
  for (const PlanarMatch& p : *m) EXPECT_LT(p.keypoint, 100) << "wrong match kept";
  EXPECT_GE(m->size(), 8u);
  const PlanarFit fit = FitFacePlane(*m, PlanarFitConfig{});
  ASSERT_TRUE(fit.accepted);
  // Where the matches are (few matches on part of the face fix its perspective terms poorly:
  // the recogniser takes the depth there, and the stereo plane the rest).
  for (const auto& ab : right) {
    EXPECT_LT(
        (ApplyHomography(fit.image_H_face, ab[0], ab[1]) - ApplyHomography(H, ab[0], ab[1])).norm(),
        1.0)
        << ab[0] << " " << ab[1];
  }
}

// Past consensus_samples triples the samples are drawn, from a fixed sequence: the same set
// for the same matches, and gross outliers among many matches still go.
TEST(PlanarFit, AffineConsensusSampledIsDeterministic) {
  std::mt19937 rng(6);
  const RigidTransform pose = RandomPose(rng, 0.5f, {0, 10, 500});
  const Eigen::Matrix3d H = HomographyOf(pose, 1000, 400, 300);
  std::uniform_real_distribution<float> ab(-30.0f, 30.0f);
  std::uniform_real_distribution<float> off(20.0f, 60.0f);
  auto m = std::make_unique<Vector<PlanarMatch, 128>>();
  for (int i = 0; i < 90; ++i) {
    const float a = ab(rng), b = ab(rng);
    const bool wrong = i % 3 == 0;
    const float dx = wrong ? off(rng) : 0.0f, dy = wrong ? -off(rng) : 0.0f;
    ASSERT_TRUE(m->push_back(MatchOf(H, a, b, dx, dy, wrong ? 1000 + i : i)));
  }
  auto again = std::make_unique<Vector<PlanarMatch, 128>>(*m);
  ASSERT_TRUE(KeepAffineConsensus(*m, PlanarFitConfig{}));
  ASSERT_TRUE(KeepAffineConsensus(*again, PlanarFitConfig{}));
  ASSERT_EQ(m->size(), again->size());
  for (size_t i = 0; i < m->size(); ++i) EXPECT_EQ((*m)[i].keypoint, (*again)[i].keypoint);
  for (const PlanarMatch& p : *m) EXPECT_LT(p.keypoint, 1000) << "gross outlier kept";
  EXPECT_GE(m->size(), 30u);  // a region of the face at least, under its perspective
}

TEST(PlanarFit, RefusesTooFewOrScatteredMatches) {
  auto m = std::make_unique<Vector<PlanarMatch, 16>>();
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(m->push_back(
        {static_cast<float>(i), static_cast<float>(i * i), 10.0f * i, 5.0f * i, 0, 0}));
  }
  EXPECT_FALSE(FitFacePlane(*m, PlanarFitConfig{}).accepted);  // 4 < 5
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.0f, 500.0f);
  m->clear();
  for (int i = 0; i < 12; ++i) ASSERT_TRUE(m->push_back({u(rng), u(rng), u(rng), u(rng), 0, 0}));
  EXPECT_FALSE(FitFacePlane(*m, PlanarFitConfig{}).accepted);  // no mapping explains them
}

TEST(PlanarFit, PoseFromHomographyInvertsTheProjection) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const RigidTransform pose = RandomPose(rng, 1.0f, {-30.0f + trial, 15, 380.0f + 10 * trial});
    if (pose.R(2, 2) > -0.1f) continue;  // the face must turn towards the camera
    const Eigen::Matrix3d H = HomographyOf(pose, 1000, 400, 300);
    RigidTransform got;
    ASSERT_TRUE(PoseFromHomography(H, 1000, 1000, 400, 300, &got));
    EXPECT_LT((got.t_mm - pose.t_mm).norm(), 1e-2f);
    EXPECT_LT(RotationAngleDeg(got.R.transpose() * pose.R), 1e-2f);
  }
}

TEST(PlanarFit, MaxImageScaleIsFocalOverDepthForAFacingFace) {
  RigidTransform pose;  // face frame = camera axes, 500 mm ahead
  pose.t_mm = {0, 0, 500};
  const Eigen::Matrix3d H = HomographyOf(pose, 1000, 400, 300);
  EXPECT_NEAR(MaxImageScale(H, 0, 0), 2.0, 1e-9);
  // Tilted by 60 degrees about the face's a axis: the a direction keeps f / Z.
  pose.R = Eigen::AngleAxisf(1.047f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  EXPECT_NEAR(MaxImageScale(HomographyOf(pose, 1000, 400, 300), 0, 0), 2.0, 1e-6);
}

// The recogniser's provisional depth: a small face (40 x 25 mm) 440 mm away at 1.7 px/mm with
// 5 to 9 matches on part of it, 0.3 px noise, 40 poses. The scale of the matches' affine map at
// their centroid is within 3 % of the true scale there on average; the fitted homography's at
// the face's centre strays at least twice as far.
TEST(PlanarFit, AffineScaleAtTheCentroidIsStableWithFewMatches) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ua(4.0f, 22.0f), ub(4.0f, 14.0f);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  constexpr int kTrials = 40;
  double mean_affine = 0, mean_homography = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const RigidTransform pose = RandomPose(rng, 0.6f, {15, -20, 440});
    const Eigen::Matrix3d H = HomographyOf(pose, 760, 512, 384);
    auto m = std::make_unique<Vector<PlanarMatch, 16>>();
    const int n = 5 + trial % 5;
    double ca = 0, cb = 0;
    for (int i = 0; i < n; ++i) {
      const float a = ua(rng), b = ub(rng), dx = noise(rng), dy = noise(rng);
      ASSERT_TRUE(m->push_back(MatchOf(H, a, b, dx, dy, i)));
      ca += a / static_cast<double>(n);
      cb += b / static_cast<double>(n);
    }
    Eigen::Matrix<double, 2, 3> affine;
    ASSERT_TRUE(FitAffine(m->data(), m->size(), &affine));
    Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
    A.topRows<2>() = affine;
    mean_affine += std::fabs(MaxImageScale(A, ca, cb) / MaxImageScale(H, ca, cb) - 1.0) / kTrials;
    Eigen::Matrix3d fitted;
    ASSERT_TRUE(FitHomography(*m, &fitted));
    mean_homography +=
        std::fabs(MaxImageScale(fitted, 20, 12.5) / MaxImageScale(H, 20, 12.5) - 1.0) / kTrials;
  }
  EXPECT_LT(mean_affine, 0.03);
  EXPECT_GT(mean_homography, 2 * mean_affine);
}

// The perspective a face shows at 400 mm, tilted by 60 degrees, stays; a homography whose w
// changes by 30 % over a 40 x 25 mm face (a face 130 mm away at most) is replaced by the
// matches' affine map.
TEST(PlanarFit, PerspectiveBeyondTheNearestDepthFallsBackToTheAffineMap) {
  RigidTransform pose;
  pose.R = Eigen::AngleAxisf(1.047f, Eigen::Vector3f::UnitY()).toRotationMatrix();
  pose.t_mm = {-10, 5, 400};
  const Eigen::Matrix3d H = HomographyOf(pose, 760, 512, 384);
  const float corners[4][2] = {{0, 0}, {40, 0}, {40, 25}, {0, 25}};
  auto m = std::make_unique<Vector<PlanarMatch, 16>>();
  const float ab[6][2] = {{5, 5}, {20, 6}, {12, 12}, {25, 10}, {8, 14}, {18, 13}};
  for (int i = 0; i < 6; ++i) ASSERT_TRUE(m->push_back(MatchOf(H, ab[i][0], ab[i][1], 0, 0, i)));
  PlanarFit fit;
  fit.image_H_face = H;
  EXPECT_FALSE(LimitPerspective(corners, 4, *m, 300.0, &fit));
  EXPECT_TRUE(fit.image_H_face.isApprox(H));

  Eigen::Matrix3d wild = H;
  wild.row(2) << 0.3 / 40.0, 0.0, 1.0;  // w from 1 to 1.3 across the face
  fit.image_H_face = wild;
  EXPECT_TRUE(LimitPerspective(corners, 4, *m, 300.0, &fit));
  Eigen::Matrix<double, 2, 3> affine;
  ASSERT_TRUE(FitAffine(*m, &affine));
  EXPECT_TRUE(fit.image_H_face.topRows<2>().isApprox(affine));
  EXPECT_EQ(fit.image_H_face.row(2), Eigen::RowVector3d(0, 0, 1));
}

TEST(AbsoluteOrientation, EqualsUmeyamaAndRecoversTheTransform) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (int trial = 0; trial < 20; ++trial) {
    const RigidTransform T = RandomPose(rng, 3.0f, {10.0f * trial, -5, 400});
    Eigen::Vector3d a[8], b[8];
    Eigen::Matrix<double, 3, 8> A, B;
    for (int i = 0; i < 8; ++i) {
      a[i] = {u(rng), u(rng), u(rng)};
      b[i] = (T.R.cast<double>() * a[i] + T.t_mm.cast<double>()) +
             Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      A.col(i) = a[i];
      B.col(i) = b[i];
    }
    RigidTransform got;
    ASSERT_TRUE(AbsoluteOrientation(a, b, nullptr, 8, &got));
    const Eigen::Matrix4d ref = Eigen::umeyama(A, B, false);
    EXPECT_LT((got.R.cast<double>() - ref.topLeftCorner<3, 3>()).norm(), 1e-5);
    EXPECT_LT((got.t_mm.cast<double>() - ref.topRightCorner<3, 1>()).norm(), 1e-3);
    EXPECT_LT(RotationAngleDeg(got.R.transpose() * T.R), 0.5f);
  }
}

TEST(AbsoluteOrientation, FourCoplanarCornersFixThePoseAndCollinearPointsDoNot) {
  const RigidTransform T = [] {
    std::mt19937 rng(5);
    return RandomPose(rng, 2.0f, {5, 6, 420});
  }();
  const Eigen::Vector3d corners[4] = {{-35, -25, 35}, {35, -25, 35}, {35, 25, 35}, {-35, 25, 35}};
  Eigen::Vector3d moved[4];
  for (int i = 0; i < 4; ++i) moved[i] = T.R.cast<double>() * corners[i] + T.t_mm.cast<double>();
  RigidTransform got;
  ASSERT_TRUE(AbsoluteOrientation(corners, moved, nullptr, 4, &got));
  EXPECT_LT(RotationAngleDeg(got.R.transpose() * T.R), 1e-3f);
  EXPECT_LT((got.t_mm - T.t_mm).norm(), 1e-3f);
  const Eigen::Vector3d line[3] = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  EXPECT_FALSE(AbsoluteOrientation(line, line, nullptr, 3, &got));
  EXPECT_FALSE(AbsoluteOrientation(corners, moved, nullptr, 2, &got));
}

TEST(PlaneFit, RansacFindsThePlaneAmongOutliers) {
  std::mt19937 rng(6);
  const Eigen::Vector3d n = Eigen::Vector3d(0.2, -0.5, -1.0).normalized();
  const double d = n.dot(Eigen::Vector3d(0, 0, 450));
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  std::uniform_real_distribution<double> u(-40.0, 40.0);
  std::normal_distribution<double> noise(0.0, 0.2);
  auto pts = std::make_unique<Vector<StereoPoint, kMaxFaceStereoPoints>>();
  for (int i = 0; i < 80; ++i) {
    StereoPoint p;
    p.x_mm = (d * n + u(rng) * e1 + u(rng) * e2 + noise(rng) * n).cast<float>();
    ASSERT_TRUE(pts->push_back(p));
  }
  for (int i = 0; i < 25; ++i) {  // outliers off the plane by 5 .. 30 mm
    StereoPoint p;
    p.x_mm = (d * n + u(rng) * e1 + u(rng) * e2 + (5.0 + i) * n).cast<float>();
    ASSERT_TRUE(pts->push_back(p));
  }
  Plane3 plane;
  PlaneFitStats stats;
  ASSERT_TRUE(FitPlaneRansac(*pts, PlaneStereoConfig{}, &plane, &stats));
  EXPECT_EQ(stats.inliers, 80);
  EXPECT_LT(std::acos(std::min(1.0, std::fabs(plane.normal.dot(n)))), 0.01);
  EXPECT_LT(plane.d_mm, 0.0);  // normal towards the camera
  EXPECT_NEAR(stats.rms_mm, 0.2, 0.08);
  for (size_t i = 0; i < pts->size(); ++i) EXPECT_EQ((*pts)[i].inlier, i < 80);
}

// A box 70 x 50 x 40 mm at cam_T_model, seen by a rotated stereo pair with distortion: exact
// observations of feature points and stereo points on its faces.
struct BoxScene {
  StereoCalibration calib;
  RigidTransform cam_T_model;
  std::vector<PoseFeatureObservation> features;
  std::vector<PoseStereoObservation> stereo;
};

BoxScene MakeBoxScene(uint32_t seed) {
  BoxScene s;
  s.calib = testing::RotatedStereoRig(756, 581, 1136);
  std::mt19937 rng(seed);
  s.cam_T_model = RandomPose(rng, 1.0f, {10, -5, 450});
  std::uniform_real_distribution<double> u(-0.45, 0.45);
  const Eigen::Vector3d half(35, 25, 20);
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {-1, 1}) {
      Eigen::Vector3d nm = Eigen::Vector3d::Zero();
      nm[axis] = sign;
      const Eigen::Vector3d nc = s.cam_T_model.R.cast<double>() * nm;
      const Eigen::Vector3d centre = s.cam_T_model.R.cast<double>() * nm.cwiseProduct(half) +
                                     s.cam_T_model.t_mm.cast<double>();
      if (nc.dot(centre) >= 0) continue;  // back face
      for (int i = 0; i < 25; ++i) {
        Eigen::Vector3d x = nm.cwiseProduct(half);
        for (int k = 0; k < 3; ++k) {
          if (k != axis) x[k] = 2.0 * half[k] * u(rng);
        }
        const Eigen::Vector3d xc =
            (s.cam_T_model.R.cast<double>() * x) + s.cam_T_model.t_mm.cast<double>();
        Eigen::Vector2d l, r;
        if (!ProjectToPixel(s.calib.left, xc, &l) ||
            !ProjectToPixel(s.calib.right, s.calib.right_R_left * xc + s.calib.right_t_left_mm, &r))
          continue;
        s.features.push_back({x, l, 0.7});
        s.stereo.push_back({l, r, nm, half[axis]});
      }
    }
  }
  return s;
}

TEST(TexturePose, RefinementReturnsToThePoseFromAPerturbedStart) {
  auto refiner = std::make_unique<TexturePoseRefiner>();
  for (uint32_t seed = 10; seed < 15; ++seed) {
    BoxScene s = MakeBoxScene(seed);
    ASSERT_GT(s.stereo.size(), 20u);
    RigidTransform start = s.cam_T_model;
    start.R = Eigen::AngleAxisf(0.05f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix() *
              start.R;
    start.t_mm += Eigen::Vector3f(4, -3, 8);
    // Some wrong observations, which the gate must drop.
    for (int i = 0; i < 3; ++i)
      s.features[static_cast<size_t>(i)].left_px += Eigen::Vector2d(25, -20);
    PoseRefineStats stats;
    ASSERT_TRUE(refiner->Refine(s.calib, s.features.data(), s.features.size(), s.stereo.data(),
                                s.stereo.size(), PoseRefineConfig{}, &start, &stats));
    EXPECT_LT((start.t_mm - s.cam_T_model.t_mm).norm(), 0.01f) << seed;
    EXPECT_LT(RotationAngleDeg(start.R.transpose() * s.cam_T_model.R), 0.01f) << seed;
    EXPECT_EQ(stats.features_used, static_cast<int>(s.features.size()) - 3);
    EXPECT_LT(stats.stereo_rms_px, 1e-3);
  }
}

TEST(TexturePose, TooFewObservationsLeaveThePoseAlone) {
  auto refiner = std::make_unique<TexturePoseRefiner>();
  BoxScene s = MakeBoxScene(20);
  RigidTransform pose = s.cam_T_model;
  pose.t_mm.x() += 3;
  const RigidTransform before = pose;
  PoseRefineStats stats;
  EXPECT_FALSE(refiner->Refine(s.calib, s.features.data(), 2, nullptr, 0, PoseRefineConfig{}, &pose,
                               &stats));
  EXPECT_EQ(pose.t_mm, before.t_mm);
}

TEST(PrintVerify, SegmentsThroughABoxAreHiddenOthersAreNot) {
  // A 2 x 2 x 2 cube at the origin of its frame, placed 100 mm ahead.
  Model cube;
  const float c[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                         {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  cube.n_corners = 8;
  for (int i = 0; i < 8; ++i) {
    for (int k = 0; k < 3; ++k) cube.corners_mm[i][k] = c[i][k];
  }
  cube.n_faces = 6;
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign : {0, 1}) {
      ModelFace& f = cube.faces[2 * axis + sign];
      f.normal[axis] = sign ? 1.0f : -1.0f;
      f.offset_mm = 1.0f;
    }
  }
  RigidTransform placed;
  placed.t_mm = {0, 0, 100};
  const Eigen::Vector3f eye = Eigen::Vector3f::Zero();
  EXPECT_TRUE(SegmentHitsConvexModel(cube, placed, eye, {0, 0, 200}, 1.0f));    // through it
  EXPECT_FALSE(SegmentHitsConvexModel(cube, placed, eye, {10, 0, 200}, 1.0f));  // beside it
  EXPECT_FALSE(SegmentHitsConvexModel(cube, placed, eye, {0, 0, 50}, 1.0f));    // before it
  EXPECT_FALSE(SegmentHitsConvexModel(cube, placed, eye, {0, 0, 99}, 1.0f));    // its front face
  EXPECT_TRUE(SegmentHitsConvexModel(cube, placed, eye, {0.5f, 0.5f, 150}, 1.0f));  // behind it
}

}  // namespace
}  // namespace sh::texture
