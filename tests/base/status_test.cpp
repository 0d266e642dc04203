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

TEST(Status, WithContextPrefixesTheMessageAndKeepsTheCode) {
  const Status s = Status::Error(StatusCode::kDataLoss, "CRC mismatch").WithContext("%s", "a.bin");
  EXPECT_EQ(s.code(), StatusCode::kDataLoss);
  EXPECT_STREQ(s.message(), "a.bin: CRC mismatch");
  EXPECT_TRUE(Status::Ok().WithContext("ignored").ok());
  EXPECT_STREQ(Status::Ok().WithContext("ignored").message(), "");
}

Result<int> Doubled(int x) {
  SH_ASSIGN_OR_RETURN(const int twice, Parse(x));
  int four_times = 0;
  SH_ASSIGN_OR_RETURN(four_times, Parse(twice));
  return four_times;
}

TEST(Status, AssignOrReturnPassesValuesOnAndReturnsErrors) {
  const Result<int> good = Doubled(3);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 12);
  const Result<int> bad = Doubled(-1);
  ASSERT_FALSE(bad.ok());
  EXPECT_STREQ(bad.status().message(), "value -1 is negative");
}

// Programming errors stop the program in every build type, with the reason.
TEST(StatusDeathTest, ResultFromAnOkStatusOrValueOfAnErrorIsFatal) {
  EXPECT_DEATH({ Result<int> r(Status::Ok()); }, "Result built from an ok Status");
  EXPECT_DEATH(
      {
        const Result<int> r = Parse(-7);
        (void)r.value();
      },
      "value -7 is negative");
  EXPECT_DEATH(
      {
        Result<int> r = Parse(-7);
        (void)*r;
      },
      "check failed");
}

}  // namespace
}  // namespace sh
