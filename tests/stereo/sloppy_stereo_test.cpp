#include "recog/stereo/sloppy_stereo.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "recog/stereo/epipolar.hpp"
#include "tests/support/stereo_scene.hpp"

namespace sh {
namespace {

using testing::ChordLine;
using testing::ProjectBoth;
using testing::RandomRig;
using testing::RandomScenePoint;

struct PointScene {
  std::vector<Eigen::Vector3d> truth;
  std::vector<StereoPoint2D> left, right;  // corner k of both images is truth[k]
};

PointScene MakePointScene(const StereoCalibration& calib, std::mt19937& rng, size_t count) {
  std::uniform_real_distribution<float> strength(0.1f, 1.0f);
  PointScene s;
  while (s.truth.size() < count) {
    const Eigen::Vector3d p = RandomScenePoint(rng);
    Eigen::Vector2d l, r;
    if (!ProjectBoth(calib, p, &l, &r)) continue;
    s.truth.push_back(p);
    s.left.push_back({static_cast<float>(l.x()), static_cast<float>(l.y()), strength(rng)});
    s.right.push_back({static_cast<float>(r.x()), static_cast<float>(r.y()), strength(rng)});
  }
  return s;
}

class SloppyStereoTest : public ::testing::Test {
 protected:
  // The matcher's workspace is large; keep it off the stack.
  std::unique_ptr<SloppyStereo> stereo_ = std::make_unique<SloppyStereo>();
  std::unique_ptr<Scene> scene_ = std::make_unique<Scene>();
};

TEST_F(SloppyStereoTest, FindsEveryTruePointMatchAndExactlyTheBruteForceSet) {
  std::mt19937 rng(10);
  for (int rig = 0; rig < 5; ++rig) {
    const StereoCalibration calib = RandomRig(rng, 1.0);
    SloppyStereoConfig config;
    config.volume = WorkingVolume::InLeftCamera({-400, -400, 300}, {500, 400, 1100});
    ASSERT_TRUE(stereo_->Configure(calib, config).ok());
    const PointScene s = MakePointScene(calib, rng, 300);
    PointStereoStats stats;
    const Status status = stereo_->MatchPoints(s.left.data(), s.left.size(), s.right.data(),
                                               s.right.size(), scene_->points, &stats);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(stats.accepted, scene_->points.size());

    std::set<std::pair<int, int>> found;
    for (const ScenePoint& p : scene_->points) {
      found.insert({p.source.left, p.source.right});
      if (p.source.left == p.source.right) {
        // Corners are stored as float pixels: 1e-4 px of rounding at ~700 mm is ~0.05 mm.
        EXPECT_LT((p.p_mm.cast<double>() - s.truth[p.source.left]).norm(), 0.1);
        EXPECT_EQ(p.quality,
                  std::min(s.left[p.source.left].strength, s.right[p.source.right].strength));
      }
    }
    for (size_t k = 0; k < s.truth.size(); ++k) {
      EXPECT_TRUE(found.count({static_cast<int>(k), static_cast<int>(k)})) << "true match " << k;
    }
    // Sloppy: spurious matches are expected too.
    EXPECT_GT(found.size(), s.truth.size());

    // The same set as testing every pair by the definition.
    std::set<std::pair<int, int>> brute;
    for (size_t i = 0; i < s.left.size(); ++i) {
      for (size_t j = 0; j < s.right.size(); ++j) {
        const Eigen::Vector2d l(s.left[i].x_px, s.left[i].y_px);
        const Eigen::Vector2d r(s.right[j].x_px, s.right[j].y_px);
        if (!(EpipolarDistancePx(calib, l, r) <= config.epipolar_tolerance_px)) continue;
        RayMidpoint m;
        if (!TriangulatePixels(calib, l, r, &m) || !(m.depth_a_mm > 0) || !(m.depth_b_mm > 0) ||
            !(m.gap_mm <= config.max_ray_gap_mm) || !config.volume.Contains(m.p_mm)) {
          continue;
        }
        brute.insert({static_cast<int>(i), static_cast<int>(j)});
      }
    }
    EXPECT_EQ(found, brute);
  }
}

TEST_F(SloppyStereoTest, PointToleranceAdmitsNoiseWithinTs) {
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.3f);
  const StereoCalibration calib = RandomRig(rng, 1.0);
  ASSERT_TRUE(stereo_->Configure(calib, SloppyStereoConfig()).ok());
  PointScene s = MakePointScene(calib, rng, 200);
  for (StereoPoint2D& p : s.right) {
    p.x_px += std::max(-0.9f, std::min(0.9f, noise(rng)));
    p.y_px += std::max(-0.9f, std::min(0.9f, noise(rng)));
  }
  ASSERT_TRUE(stereo_
                  ->MatchPoints(s.left.data(), s.left.size(), s.right.data(), s.right.size(),
                                scene_->points)
                  .ok());
  std::set<int> matched;
  for (const ScenePoint& p : scene_->points) {
    if (p.source.left == p.source.right) matched.insert(p.source.left);
  }
  // |offset| <= 0.9 * sqrt(2) < T_s = 2 px, so the epipolar test keeps every true pair; the
  // ray gap (<= ~1 mm here) stays under max_ray_gap_mm.
  EXPECT_EQ(matched.size(), s.truth.size());
}

TEST_F(SloppyStereoTest, FullSceneStopsWithResourceExhausted) {
  std::mt19937 rng(12);
  const StereoCalibration calib = RandomRig(rng, 0.0);
  SloppyStereoConfig config;
  config.epipolar_tolerance_px = 50.0f;  // very sloppy: many matches per corner
  config.max_ray_gap_mm = 100.0f;
  ASSERT_TRUE(stereo_->Configure(calib, config).ok());
  const PointScene s = MakePointScene(calib, rng, 1000);
  PointStereoStats stats;
  const Status status = stereo_->MatchPoints(s.left.data(), s.left.size(), s.right.data(),
                                             s.right.size(), scene_->points, &stats);
  EXPECT_EQ(status.code(), StatusCode::kResourceExhausted) << status.message();
  EXPECT_TRUE(stats.truncated);
  EXPECT_EQ(scene_->points.size(), kMaxScenePoints);
  EXPECT_EQ(stats.accepted, kMaxScenePoints);
}

TEST_F(SloppyStereoTest, BadInputIsRefused) {
  std::mt19937 rng(13);
  const StereoCalibration calib = RandomRig(rng, 0.0);
  StereoPoint2D p[2] = {{10, 10, 1}, {20, 20, 1}};
  EXPECT_EQ(stereo_->MatchPoints(p, 2, p, 2, scene_->points).code(),
            StatusCode::kFailedPrecondition);
  SloppyStereoConfig config;
  config.epipolar_tolerance_px = -1.0f;
  EXPECT_FALSE(stereo_->Configure(calib, config).ok());
  config = SloppyStereoConfig();
  config.volume.max_mm.z() = config.volume.min_mm.z();
  EXPECT_FALSE(stereo_->Configure(calib, config).ok());
  StereoCalibration bad = calib;
  bad.right_t_left_mm.setZero();
  EXPECT_FALSE(stereo_->Configure(bad, SloppyStereoConfig()).ok());

  ASSERT_TRUE(stereo_->Configure(calib, SloppyStereoConfig()).ok());
  p[1].x_px = std::numeric_limits<float>::quiet_NaN();
  const Status nan = stereo_->MatchPoints(p, 2, p, 1, scene_->points);
  EXPECT_EQ(nan.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(nan.message()).find("left corner 1"), std::string::npos) << nan.message();
  EXPECT_EQ(stereo_->MatchPoints(p, kMaxStereoCorners + 1, p, 1, scene_->points).code(),
            StatusCode::kOutOfRange);

  StereoLine2D line = ChordLine({10, 10}, {100, 10});
  line.direction = {0.0f, 0.0f};
  EXPECT_EQ(stereo_->MatchLines(&line, 1, &line, 1, scene_->lines).code(),
            StatusCode::kInvalidArgument);
  line = ChordLine({10, 10}, {100, 10});
  line.segment_count = kMaxStereoLineSegments + 1;
  EXPECT_EQ(stereo_->MatchLines(&line, 1, &line, 1, scene_->lines).code(),
            StatusCode::kInvalidArgument);
}

struct LineScene {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> truth;
  std::vector<StereoLine2D> left, right;
};

LineScene MakeLineScene(const StereoCalibration& calib, std::mt19937& rng, size_t count,
                        double length_mm) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LineScene s;
  while (s.truth.size() < count) {
    const Eigen::Vector3d a = RandomScenePoint(rng);
    const Eigen::Vector3d d = Eigen::Vector3d(u(rng), u(rng), 0.3 * u(rng)).normalized();
    const Eigen::Vector3d b = a + length_mm * d;
    Eigen::Vector2d la, ra, lb, rb;
    if (!ProjectBoth(calib, a, &la, &ra) || !ProjectBoth(calib, b, &lb, &rb)) continue;
    s.truth.push_back({a, b});
    s.left.push_back(ChordLine(la, lb));
    s.right.push_back(ChordLine(ra, rb));
  }
  return s;
}

TEST_F(SloppyStereoTest, FindsEveryWellConditionedTrueLineWithItsSegment) {
  std::mt19937 rng(20);
  for (int rig = 0; rig < 3; ++rig) {
    const StereoCalibration calib = RandomRig(rng, 0.0);
    SloppyStereoConfig config;
    ASSERT_TRUE(stereo_->Configure(calib, config).ok());
    const LineScene s = MakeLineScene(calib, rng, 100, 80.0);
    LineStereoStats stats;
    const Status status = stereo_->MatchLines(s.left.data(), s.left.size(), s.right.data(),
                                              s.right.size(), scene_->lines, &stats);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(stats.pairs, s.left.size() * s.right.size());
    EXPECT_EQ(stats.accepted, scene_->lines.size());

    std::set<int> found_true;
    for (const SceneLine& l : scene_->lines) {
      EXPECT_GE(l.quality, config.min_overlap_mm);
      EXPECT_NEAR(l.quality, l.length_mm(), 1e-3 * l.length_mm());  // one overlap interval
      if (l.source.left != l.source.right) continue;
      found_true.insert(l.source.left);
      const auto& [a, b] = s.truth[l.source.left];
      // Both supports are the whole segment, so the overlap is the segment (either order).
      const double err =
          std::min((l.a_mm.cast<double>() - a).norm() + (l.b_mm.cast<double>() - b).norm(),
                   (l.a_mm.cast<double>() - b).norm() + (l.b_mm.cast<double>() - a).norm());
      EXPECT_LT(err, 0.05) << "line " << l.source.left;
    }
    // Every true line is found unless its planes are within min_plane_angle of parallel.
    const Eigen::Vector3d baseline = RightCentreInLeft(calib);
    for (size_t k = 0; k < s.truth.size(); ++k) {
      const auto& [a, b] = s.truth[k];
      const Eigen::Vector3d n_left = a.cross(b).normalized();
      const Eigen::Vector3d n_right = (a - baseline).cross(b - baseline).normalized();
      const double sin_angle = n_left.cross(n_right).norm();
      if (sin_angle > std::sin((config.min_plane_angle_deg + 0.5) * 3.14159265 / 180.0)) {
        EXPECT_TRUE(found_true.count(static_cast<int>(k))) << "true line " << k;
      } else if (sin_angle < std::sin((config.min_plane_angle_deg - 0.5) * 3.14159265 / 180.0)) {
        EXPECT_FALSE(found_true.count(static_cast<int>(k))) << "degenerate line " << k;
      }
    }
    // Fused multiply-add (aarch64) and x86 round differently near the acceptance limits.
    EXPECT_GT(found_true.size(), s.truth.size() * 3 / 4);
    EXPECT_GT(scene_->lines.size(), found_true.size());  // sloppy: spurious ones as well
  }
}

TEST_F(SloppyStereoTest, LineSupportIsTheOverlapAndRespectsMinimum) {
  // One 3-D segment seen whole on the left, and only its first 30 mm on the right: the 3-D line
  // spans the common 30 mm. With min_overlap 40 mm the pair is rejected.
  std::mt19937 rng(21);
  const StereoCalibration calib = RandomRig(rng, 0.0);
  const Eigen::Vector3d a(40, 0, 700), b(40, 100, 720);  // mostly vertical: well conditioned
  const Eigen::Vector3d c = a + 0.3 * (b - a);
  Eigen::Vector2d la, ra, lb, rb, lc, rc;
  ASSERT_TRUE(ProjectBoth(calib, a, &la, &ra) && ProjectBoth(calib, b, &lb, &rb) &&
              ProjectBoth(calib, c, &lc, &rc));
  const StereoLine2D left = ChordLine(la, lb);
  StereoLine2D right = ChordLine(ra, rb);
  right.segments[0] = {static_cast<float>(ra.x()), static_cast<float>(ra.y()),
                       static_cast<float>(rc.x()), static_cast<float>(rc.y())};
  SloppyStereoConfig config;
  ASSERT_TRUE(stereo_->Configure(calib, config).ok());
  ASSERT_TRUE(stereo_->MatchLines(&left, 1, &right, 1, scene_->lines).ok());
  ASSERT_EQ(scene_->lines.size(), 1u);
  const double overlap = (c - a).norm();
  EXPECT_NEAR(scene_->lines[0].quality, overlap, 0.01);
  EXPECT_NEAR(scene_->lines[0].length_mm(), overlap, 0.01);

  config.min_overlap_mm = static_cast<float>(overlap + 10.0);
  ASSERT_TRUE(stereo_->Configure(calib, config).ok());
  LineStereoStats stats;
  ASSERT_TRUE(stereo_->MatchLines(&left, 1, &right, 1, scene_->lines, &stats).ok());
  EXPECT_EQ(scene_->lines.size(), 0u);
  EXPECT_EQ(stats.rejected_overlap, 1u);

  // A working volume that ends 20 mm along the segment clips the overlap to 20 mm.
  config = SloppyStereoConfig();
  config.volume = WorkingVolume::InLeftCamera(
      {-500, -500, 300}, {500, static_cast<float>(a.y() + 20.0 * (b - a).normalized().y()), 1100});
  ASSERT_TRUE(stereo_->Configure(calib, config).ok());
  ASSERT_TRUE(stereo_->MatchLines(&left, 1, &right, 1, scene_->lines).ok());
  ASSERT_EQ(scene_->lines.size(), 1u);
  EXPECT_NEAR(scene_->lines[0].quality, 20.0, 0.01);
}

TEST_F(SloppyStereoTest, LinesWithoutSupportAreUnusable) {
  std::mt19937 rng(22);
  const StereoCalibration calib = RandomRig(rng, 0.0);
  ASSERT_TRUE(stereo_->Configure(calib, SloppyStereoConfig()).ok());
  StereoLine2D line = ChordLine({100, 100}, {300, 400});
  line.segment_count = 0;
  LineStereoStats stats;
  ASSERT_TRUE(stereo_->MatchLines(&line, 1, &line, 1, scene_->lines, &stats).ok());
  EXPECT_EQ(stats.unusable_lines, 2u);
  EXPECT_EQ(stats.pairs, 0u);
}

}  // namespace
}  // namespace sh
