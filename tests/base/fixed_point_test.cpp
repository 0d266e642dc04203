#include "recog/base/fixed_point.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace sh {
namespace {

TEST(FixedPoint, RoundTripsWithinHalfAnLsb) {
  for (double v = -500.0; v < 500.0; v += 0.37) {
    const QCoordMm q = QCoordMm::FromDouble(v);
    EXPECT_NEAR(q.ToDouble(), v, 0.5 / QCoordMm::kScale) << v;
  }
}

TEST(FixedPoint, SaturatesInsteadOfWrapping) {
  EXPECT_EQ(QCoordMm::FromDouble(1e6).raw(), INT16_MAX);
  EXPECT_EQ(QCoordMm::FromDouble(-1e6).raw(), INT16_MIN);
  EXPECT_EQ(UQVote::FromDouble(2.0).raw(), UINT16_MAX);
  EXPECT_EQ(UQVote::FromDouble(-1.0).raw(), 0);
  EXPECT_EQ(QUnit::FromDouble(std::nan("")).raw(), 0);
}

TEST(FixedPoint, RangeMatchesTheFormat) {
  EXPECT_DOUBLE_EQ(QUnit::kMax, 2.0 - 1.0 / 16384.0);
  EXPECT_DOUBLE_EQ(QUnit::kMin, -2.0);
  EXPECT_TRUE(QCoordMm::Representable(511.9));
  EXPECT_FALSE(QCoordMm::Representable(513.0));
  static_assert(sizeof(QCoordMm::Raw) == 2);
  static_assert(sizeof(Q<16, 16>::Raw) == 4);
}

}  // namespace
}  // namespace sh
