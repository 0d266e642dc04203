#include "recog/base/vector.hpp"

#include <gtest/gtest.h>

namespace sh {
namespace {

int Sum(const Vector<int>& v) {
  int s = 0;
  for (int x : v) s += x;
  return s;
}

TEST(Vector, PushUntilFullThenRefuses) {
  Vector<int, 3> v;
  EXPECT_TRUE(v.push_back(1));
  EXPECT_TRUE(v.push_back(2));
  EXPECT_TRUE(v.push_back(3));
  EXPECT_TRUE(v.full());
  EXPECT_FALSE(v.push_back(4));
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(Sum(v), 6);  // size-erased base sees the same elements
}

TEST(Vector, SwapRemoveAndResize) {
  Vector<int, 4> v;
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(v.push_back(i * 10));
  v.swap_remove(0);
  EXPECT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0], 30);
  EXPECT_FALSE(v.resize(9));
  EXPECT_EQ(v.size(), 4u);
  EXPECT_TRUE(v.resize(1));
  EXPECT_EQ(v.size(), 1u);
}

TEST(Vector, CopyKeepsElements) {
  Vector<int, 4> a;
  ASSERT_TRUE(a.push_back(7));
  Vector<int, 4> b = a;
  a[0] = 8;
  EXPECT_EQ(b[0], 7);
}

}  // namespace
}  // namespace sh
