#include "recog/base/status.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace sh {
namespace {

Result<int> Parse(int x) {
  if (x < 0) return Status::Error(StatusCode::kOutOfRange, "value %d is negative", x);
  return x * 2;
}

TEST(Status, CarriesCodeAndFormattedMessage) {
  const Result<int> bad = Parse(-3);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kOutOfRange);
  EXPECT_STREQ(bad.status().message(), "value -3 is negative");
  const Result<int> good = Parse(4);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 8);
}

TEST(Status, TruncatesLongMessages) {
  const std::string longer(500, 'x');
  const Status s = Status::Error(StatusCode::kInvalidArgument, "%s", longer.c_str());
  EXPECT_EQ(std::strlen(s.message()), Status::kMaxMessage - 1);
}

}  // namespace
}  // namespace sh
