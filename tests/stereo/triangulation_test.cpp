#include "recog/stereo/triangulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "recog/stereo/epipolar.hpp"
#include "recog/stereo/working_volume.hpp"
#include "tests/support/stereo_scene.hpp"

namespace sh {
namespace {

using testing::ChordLine;
using testing::ProjectBoth;
using testing::RandomRig;
using testing::RandomScenePoint;

TEST(Triangulation, ProjectThenTriangulateReturnsThePoint) {
  std::mt19937 rng(1);
  double worst_mm = 0.0;
  int n = 0;
  for (int rig = 0; rig < 20; ++rig) {
    const StereoCalibration calib = RandomRig(rng, 1.0);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d p = RandomScenePoint(rng);
      Eigen::Vector2d l, r;
      if (!ProjectBoth(calib, p, &l, &r)) continue;
      RayMidpoint m;
      ASSERT_TRUE(TriangulatePixels(calib, l, r, &m));
      worst_mm = std::max(worst_mm, (m.p_mm - p).norm());
      EXPECT_LT(m.gap_mm, 1e-6);
      EXPECT_GT(m.depth_a_mm, 0.0);
      EXPECT_GT(m.depth_b_mm, 0.0);
      // The true right pixel lies on the epipolar curve of the left one.
      EXPECT_LT(EpipolarDistancePx(calib, l, r), 1e-6);
      ++n;
    }
  }
  ASSERT_GT(n, 1000);
  EXPECT_LT(worst_mm, 0.01);
}

TEST(Triangulation, EpipolarDistanceGrowsWithOffsetAcrossTheLine) {
  std::mt19937 rng(2);
  const StereoCalibration calib = RandomRig(rng, 0.0);
  const Eigen::Vector3d p(60, 10, 700);
  Eigen::Vector2d l, r;
  ASSERT_TRUE(ProjectBoth(calib, p, &l, &r));
  // Without distortion and with fx = fy, moving perpendicular to the line by d pixels gives d.
  StereoCalibration square = calib;
  square.right.fy = square.right.fx;
  ASSERT_TRUE(ProjectBoth(square, p, &l, &r));
  const Eigen::Vector3d line =
      RightEpipolarLine(EssentialMatrix(square), UndistortPixel(square.left, l));
  const Eigen::Vector2d normal(line.x(), line.y());
  for (double d : {0.5, 1.0, 3.0}) {
    EXPECT_NEAR(EpipolarDistancePx(square, l, r + d * normal), d, 1e-6);
  }
}

TEST(Triangulation, MidpointOfSkewRays) {
  // Rays along x at y = -1 and along y at z = 0, x = 0, shifted by 2 in z: gap 2, midpoint z = 1.
  RayMidpoint m;
  ASSERT_TRUE(TriangulateMidpoint(Eigen::Vector3d(-5, 0, 0), Eigen::Vector3d::UnitX(),
                                  Eigen::Vector3d(0, -5, 2), Eigen::Vector3d::UnitY(), &m));
  EXPECT_LT((m.p_mm - Eigen::Vector3d(0, 0, 1)).norm(), 1e-12);
  EXPECT_NEAR(m.gap_mm, 2.0, 1e-12);
  EXPECT_NEAR(m.depth_a_mm, 5.0, 1e-12);
  EXPECT_NEAR(m.depth_b_mm, 5.0, 1e-12);
  EXPECT_FALSE(TriangulateMidpoint(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                   Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), &m));
}

// Plane of one camera's image line, in the left frame.
Plane3 LinePlane(const StereoCalibration& calib, bool left, const StereoLine2D& line) {
  const CameraIntrinsics& cam = left ? calib.left : calib.right;
  const Eigen::Vector2d a(line.segments[0].x0_px, line.segments[0].y0_px);
  const Eigen::Vector2d b(line.segments[0].x1_px, line.segments[0].y1_px);
  const Eigen::Vector2d samples[3] = {a, 0.5 * (a + b), b};
  Eigen::Vector3d n;
  EXPECT_TRUE(FitLinePlaneNormal(cam, samples, 3, &n));
  Plane3 plane;
  plane.normal = left ? n : Eigen::Vector3d(calib.right_R_left.transpose() * n);
  plane.d_mm = left ? 0.0 : plane.normal.dot(RightCentreInLeft(calib));
  return plane;
}

double DistanceToLine(const Line3& line, const Eigen::Vector3d& p) {
  const Eigen::Vector3d v = p - line.point_mm;
  return (v - v.dot(line.direction) * line.direction).norm();
}

void CheckLineRecovery(double distortion, double tolerance_mm, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int n = 0;
  double worst_mm = 0.0;
  for (int rig = 0; rig < 10; ++rig) {
    const StereoCalibration calib = RandomRig(rng, distortion);
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector3d a = RandomScenePoint(rng);
      const Eigen::Vector3d b = a + 60.0 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      Eigen::Vector2d la, ra, lb, rb;
      if (!ProjectBoth(calib, a, &la, &ra) || !ProjectBoth(calib, b, &lb, &rb)) continue;
      const StereoLine2D left = ChordLine(la, lb), right = ChordLine(ra, rb);
      Line3 line;
      // Only well-conditioned pairs: planes at least 10 degrees apart.
      if (!IntersectPlanes(LinePlane(calib, true, left), LinePlane(calib, false, right),
                           std::sin(10.0 * 3.14159265 / 180.0), &line)) {
        continue;
      }
      ++n;
      worst_mm = std::max({worst_mm, DistanceToLine(line, a), DistanceToLine(line, b)});
      // Back-projecting the segment end points gives back the 3-D end points.
      double sa = 0, sb = 0;
      ASSERT_TRUE(RayLineParameter(line, Eigen::Vector3d::Zero(), PixelRay(calib.left, la), &sa));
      ASSERT_TRUE(RayLineParameter(line, Eigen::Vector3d::Zero(), PixelRay(calib.left, lb), &sb));
      worst_mm = std::max({worst_mm, (line.At(sa) - a).norm(), (line.At(sb) - b).norm()});
    }
  }
  ASSERT_GT(n, 250);  // well-conditioned cases among the random ones (platform-dependent count)
  EXPECT_LT(worst_mm, tolerance_mm);
}

// Segment rays are single precision: at 0.5-1 m a ray is exact to about 1e-3 mm.
TEST(Triangulation, LineFromTwoPlanesRecoversRandomSegments) { CheckLineRecovery(0.0, 1e-2, 3); }

TEST(Triangulation, LineRecoveryWithDistortionUsesTheChordPlane) {
  // The image of a 3-D segment is curved; the plane through the rays of the chord's ends and
  // middle still contains both ends exactly, so the 3-D line passes through them up to the
  // curvature's effect on the middle sample (sub-millimetre for 60 mm segments).
  CheckLineRecovery(1.0, 0.5, 4);
}

TEST(Triangulation, NearlyParallelPlanesAreRejected) {
  Plane3 a, b;
  a.normal = Eigen::Vector3d::UnitZ();
  b.normal = Eigen::Vector3d(0, std::sin(0.01), std::cos(0.01));
  Line3 line;
  EXPECT_FALSE(IntersectPlanes(a, b, std::sin(0.02), &line));
  ASSERT_TRUE(IntersectPlanes(a, b, std::sin(0.005), &line));
  EXPECT_NEAR(std::fabs(line.direction.x()), 1.0, 1e-12);
}

TEST(Triangulation, InterpretationPlaneAngleOfEdges) {
  std::mt19937 rng(4);
  StereoCalibration calib = RandomRig(rng, 0.0);
  // A rectified pair: the right camera 120 mm along the left camera's x axis.
  calib.right_R_left = Eigen::Matrix3d::Identity();
  calib.right_t_left_mm = Eigen::Vector3d(-120.0, 0.0, 0.0);
  // An edge parallel to the baseline lies in one epipolar plane: both planes coincide.
  EXPECT_NEAR(InterpretationPlaneAngleDeg(calib, {-20.0, 5.0, 500.0}, {20.0, 5.0, 500.0}), 0.0,
              1e-9);
  // A vertical edge midway between the cameras at depth z: the planes meet at 2 atan(B / 2z).
  const double expected = 2.0 * std::atan(60.0 / 500.0) * 180.0 / 3.14159265358979323846;
  EXPECT_NEAR(InterpretationPlaneAngleDeg(calib, {60.0, -15.0, 500.0}, {60.0, 15.0, 500.0}),
              expected, 1e-9);
  // Turning the edge in its depth plane towards the baseline closes the angle monotonically.
  double previous = 90.0;
  for (double deg = 90.0; deg >= 0.0; deg -= 10.0) {
    const double r = deg * 3.14159265358979323846 / 180.0;
    const Eigen::Vector3d d(15.0 * std::cos(r), 15.0 * std::sin(r), 0.0);
    const Eigen::Vector3d mid(60.0, 0.0, 500.0);
    const double angle = InterpretationPlaneAngleDeg(calib, mid - d, mid + d);
    EXPECT_LE(angle, previous + 1e-12);
    previous = angle;
  }
  EXPECT_NEAR(previous, 0.0, 1e-9);
  // Degenerate: a point, not a segment.
  EXPECT_EQ(InterpretationPlaneAngleDeg(calib, {1.0, 2.0, 300.0}, {1.0, 2.0, 300.0}), 0.0);
  // The angle belongs to the pair, not to either camera: on a general rig it is the same seen
  // from the right camera with the roles of the cameras swapped.
  for (int rig = 0; rig < 10; ++rig) {
    const StereoCalibration c = RandomRig(rng, 0.0);
    StereoCalibration swapped = c;
    swapped.right_R_left = c.right_R_left.transpose();
    swapped.right_t_left_mm = -(c.right_R_left.transpose() * c.right_t_left_mm);
    const Eigen::Vector3d a = RandomScenePoint(rng), b = RandomScenePoint(rng);
    const Eigen::Vector3d a_right = c.right_R_left * a + c.right_t_left_mm;
    const Eigen::Vector3d b_right = c.right_R_left * b + c.right_t_left_mm;
    EXPECT_NEAR(InterpretationPlaneAngleDeg(c, a, b),
                InterpretationPlaneAngleDeg(swapped, a_right, b_right), 1e-7);
  }
}

TEST(WorkingVolume, ContainsAndClipInATableFrame) {
  // Table 700 mm in front, tilted 30 degrees about x; box 400 x 400 x 70 mm on it.
  RigidTransform left_T_table;
  left_T_table.R = Eigen::AngleAxisf(0.5236f, Eigen::Vector3f::UnitX()).toRotationMatrix();
  left_T_table.t_mm = Eigen::Vector3f(0, 0, 700);
  const WorkingVolume v = WorkingVolume::InFrame(left_T_table, Eigen::Vector3f(-200, -200, 0),
                                                 Eigen::Vector3f(200, 200, 70));
  const Eigen::Vector3d centre = (left_T_table * Eigen::Vector3f(0, 0, 35)).cast<double>();
  EXPECT_TRUE(v.Contains(centre));
  EXPECT_FALSE(v.Contains((left_T_table * Eigen::Vector3f(0, 0, 80)).cast<double>()));
  EXPECT_FALSE(v.Contains((left_T_table * Eigen::Vector3f(201, 0, 10)).cast<double>()));
  // A line along the table's x axis through the centre crosses 400 mm of box.
  Line3 line;
  line.point_mm = centre;
  line.direction = left_T_table.R.col(0).cast<double>();
  double s0 = 0, s1 = 0;
  ASSERT_TRUE(v.Clip(line, &s0, &s1));
  EXPECT_NEAR(s1 - s0, 400.0, 1e-3);
  EXPECT_NEAR(s0, -200.0, 1e-3);
  // Parallel to the table, 100 mm above it: misses.
  line.point_mm = (left_T_table * Eigen::Vector3f(0, 0, 100)).cast<double>();
  EXPECT_FALSE(v.Clip(line, &s0, &s1));
}

}  // namespace
}  // namespace sh
