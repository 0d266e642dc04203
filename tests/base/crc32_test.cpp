#include "recog/base/crc32.hpp"

#include <gtest/gtest.h>

#include <cstring>

namespace sh {
namespace {

TEST(Crc32, MatchesTheStandardCheckValue) {
  // The CRC-32/ISO-HDLC check value of "123456789".
  EXPECT_EQ(Crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(Crc32("", 0), 0u);
}

TEST(Crc32, ContinuesAcrossChunks) {
  const char* text = "stereo geometric hashing";
  const size_t n = std::strlen(text);
  EXPECT_EQ(Crc32(text + 6, n - 6, Crc32(text, 6)), Crc32(text, n));
}

}  // namespace
}  // namespace sh
