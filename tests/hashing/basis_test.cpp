// Basis frames are invariant: moving the features by T moves the frame by T.
#include "recog/hashing/basis.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace sh {
namespace {

RigidTransform RandomTransform(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const Eigen::Quaternionf q = Eigen::Quaternionf(u(rng), u(rng), u(rng), u(rng)).normalized();
  return {q.toRotationMatrix(), Eigen::Vector3f(u(rng), u(rng), u(rng)) * 300.0f};
}

Eigen::Vector3f RandomPoint(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-25.0f, 25.0f);
  return {u(rng), u(rng), u(rng)};
}

void ExpectSameTransform(const RigidTransform& a, const RigidTransform& b) {
  EXPECT_TRUE(a.R.isApprox(b.R, 1e-4f)) << a.R << "\n" << b.R;
  EXPECT_LT((a.t_mm - b.t_mm).norm(), 1e-2f);
}

TEST(Basis, FramesAreOrthonormalAndRightHanded) {
  std::mt19937 rng(1);
  BasisLimits limits;
  for (int i = 0; i < 100; ++i) {
    RigidTransform f;
    if (!ThreePointFrame(HashFunction::kThreePointsCentroid, RandomPoint(rng), RandomPoint(rng),
                         RandomPoint(rng), limits, &f))
      continue;
    EXPECT_TRUE((f.R * f.R.transpose()).isIdentity(1e-5f));
    EXPECT_NEAR(f.R.determinant(), 1.0f, 1e-5f);
  }
}

TEST(Basis, ThreePointFramesMoveWithThePoints) {
  std::mt19937 rng(2);
  BasisLimits limits;
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3f p0 = RandomPoint(rng), p1 = RandomPoint(rng), p2 = RandomPoint(rng);
    const RigidTransform T = RandomTransform(rng);
    for (HashFunction hf : {HashFunction::kThreePointsFirst, HashFunction::kThreePointsCentroid}) {
      RigidTransform f, g;
      if (!ThreePointFrame(hf, p0, p1, p2, limits, &f)) continue;
      ASSERT_TRUE(ThreePointFrame(hf, T * p0, T * p1, T * p2, limits, &g));
      ExpectSameTransform(g, f * T.Inverse());
      // The shape point is invariant.
      EXPECT_LT(
          (TriangleShapePoint(p0, p1, p2) - TriangleShapePoint(T * p0, T * p1, T * p2)).norm(),
          1e-3f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(Basis, LineFramesMoveWithTheLines) {
  std::mt19937 rng(3);
  BasisLimits limits;
  int checked = 0;
  for (int i = 0; i < 300; ++i) {
    const RigidTransform T = RandomTransform(rng);
    const BasisLine3 l0{RandomPoint(rng), RandomPoint(rng).normalized()};
    const BasisLine3 l1{RandomPoint(rng), RandomPoint(rng).normalized()};
    const Eigen::Vector3f p = RandomPoint(rng) * 2.0f;
    const BasisLine3 m0{T * l0.point, T.Rotate(l0.direction)},
        m1{T * l1.point, T.Rotate(l1.direction)};
    RigidTransform f, g;
    if (TwoLineFrame(l0, l1, limits, &f)) {
      ASSERT_TRUE(TwoLineFrame(m0, m1, limits, &g));
      ExpectSameTransform(g, f * T.Inverse());
      ++checked;
    }
    for (HashFunction hf : {HashFunction::kLinePointFoot, HashFunction::kLinePointMidway}) {
      if (!LinePointFrame(hf, l0, p, limits, &f)) continue;
      ASSERT_TRUE(LinePointFrame(hf, m0, T * p, limits, &g));
      ExpectSameTransform(g, f * T.Inverse());
      // y points at the point, which lies in the xy-plane at distance d (hash fn 4) or d / 2
      // (hash fn 5, origin midway) from the origin.
      const Eigen::Vector3f q = f * p;
      const float d = PointLineDistance(l0, p);
      EXPECT_NEAR(q.z(), 0.0f, 1e-3f);
      EXPECT_NEAR(q.x(), 0.0f, 1e-3f);
      EXPECT_NEAR(q.y(), hf == HashFunction::kLinePointFoot ? d : d / 2, 1e-3f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(Basis, RejectsDegenerateBases) {
  BasisLimits limits;
  RigidTransform f;
  const Eigen::Vector3f a(0, 0, 0), b(30, 0, 0), c(60, 0.5f, 0);
  EXPECT_FALSE(ThreePointFrame(HashFunction::kThreePointsFirst, a, b, c, limits, &f));  // collinear
  const BasisLine3 x{{0, 0, 0}, {1, 0, 0}};
  const BasisLine3 nearly_parallel{{0, 10, 0}, Eigen::Vector3f(1, 0.3f, 0).normalized()};
  EXPECT_FALSE(TwoLineFrame(x, nearly_parallel, limits, &f));  // 16.7 degrees < 37
  EXPECT_FALSE(LinePointFrame(HashFunction::kLinePointMidway, x, {5, 10, 0}, limits, &f));  // 10 mm
  EXPECT_FALSE(LinePointFrame(HashFunction::kLinePointMidway, x, {5, 80, 0}, limits, &f));  // 80 mm
  EXPECT_TRUE(LinePointFrame(HashFunction::kLinePointMidway, x, {5, 40, 0}, limits, &f));
}

}  // namespace
}  // namespace sh
