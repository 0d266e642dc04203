#include "recog/image/binning.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace sh {
namespace {

TEST(Binning, FactorIsTheSmallestThatFitsAFrame) {
  EXPECT_EQ(*BinFactorFor(kMaxImageWidth, kMaxImageHeight), 1);
  EXPECT_EQ(*BinFactorFor(756, 581), 1);
  EXPECT_EQ(*BinFactorFor(kMaxImageWidth + 1, 100), 2);
  EXPECT_EQ(*BinFactorFor(100, kMaxImageHeight + 1), 2);
  EXPECT_EQ(*BinFactorFor(2448, 2048), 2);
  EXPECT_EQ(*BinFactorFor(kMaxSensorWidth, kMaxSensorHeight), 2);
  EXPECT_LE(BinnedSize(kMaxSensorWidth, 2), kMaxImageWidth);
  EXPECT_LE(BinnedSize(kMaxSensorHeight, 2), kMaxImageHeight);
}

TEST(Binning, SizesBeyondTheLargestSensorOrEmptyAreRefused) {
  for (auto [w, h] :
       {std::pair{kMaxSensorWidth + 1, 10}, {10, kMaxSensorHeight + 1}, {0, 10}, {10, -1}}) {
    const Result<int> f = BinFactorFor(w, h);
    ASSERT_FALSE(f.ok()) << w << "x" << h;
    EXPECT_EQ(f.status().code(), StatusCode::kOutOfRange);
    EXPECT_NE(std::strstr(f.status().message(), "2592x2048"), nullptr) << f.status().message();
  }
}

TEST(Binning, GrayBlocksAreRoundedMeansAndTheRemainderIsDropped) {
  // 5 x 3 binned by 2: two columns and one row of blocks; the last column and row are dropped.
  const uint8_t px[] = {0,  1,  10, 20, 99,  //
                        2,  2,  30, 41, 99,  //
                        99, 99, 99, 99, 99};
  uint8_t out[2] = {};
  ASSERT_TRUE(BinGray({px, 5, 3, 5}, 2, {out, 2, 1, 2}).ok());
  EXPECT_EQ(out[0], 1);                   // (0 + 1 + 2 + 2) / 4 = 1.25
  EXPECT_EQ(out[1], 25);                  // (10 + 20 + 30 + 41) / 4 = 25.25
  const uint8_t halves[] = {1, 2, 1, 2};  // 1.5 rounds up
  ASSERT_TRUE(BinGray({halves, 2, 2, 2}, 2, {out, 1, 1, 1}).ok());
  EXPECT_EQ(out[0], 2);
  // Factor 1 copies.
  uint8_t copy[15] = {};
  ASSERT_TRUE(BinGray({px, 5, 3, 5}, 1, {copy, 5, 3, 5}).ok());
  EXPECT_EQ(std::memcmp(copy, px, sizeof(px)), 0);
}

// Every factor, on an image with a remainder and a wider stride, against the mean taken here.
TEST(Binning, EveryFactorGivesTheRoundedBlockMean) {
  const int w = 37, h = 29, stride = 40;
  std::vector<uint8_t> px(static_cast<size_t>(stride) * h);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>((i * 2654435761u) >> 24);
  for (int f = 1; f <= kMaxBinFactor; ++f) {
    const int bw = BinnedSize(w, f), bh = BinnedSize(h, f);
    std::vector<uint8_t> out(static_cast<size_t>(bw + 3) * bh, 0);
    ASSERT_TRUE(BinGray({px.data(), w, h, stride}, f, {out.data(), bw, bh, bw + 3}).ok());
    for (int y = 0; y < bh; ++y) {
      for (int x = 0; x < bw; ++x) {
        int sum = 0;
        for (int dy = 0; dy < f; ++dy) {
          const uint8_t* row = &px[static_cast<size_t>(y * f + dy) * stride];
          for (int dx = 0; dx < f; ++dx) sum += row[(x * f) + dx];
        }
        ASSERT_EQ(out[static_cast<size_t>(y) * (bw + 3) + x], (sum + f * f / 2) / (f * f))
            << f << ": " << x << "," << y;
      }
    }
  }
}

TEST(Binning, ColourChannelsAreBinnedApart) {
  std::vector<Rgb8> px(8);
  for (int i = 0; i < 8; ++i) px[i] = Rgb8{uint8_t(i), uint8_t(100 + i), uint8_t(255 - i)};
  Rgb8 out[2];
  ASSERT_TRUE(BinRgb({px.data(), 4, 2, 4}, 2, {out, 2, 1, 2}).ok());
  // Block 0 holds pixels 0, 1, 4, 5 (mean 2.5); block 1 holds 2, 3, 6, 7 (mean 4.5).
  EXPECT_EQ(out[0].r, 3);
  EXPECT_EQ(out[0].g, 103);
  EXPECT_EQ(out[0].b, 253);  // 252.5 rounds up
  EXPECT_EQ(out[1].r, 5);
  EXPECT_EQ(out[1].b, 251);
}

TEST(Binning, WrongOutputSizeOrFactorIsRefused) {
  std::vector<uint8_t> px(64, 7), out(64);
  EXPECT_EQ(BinGray({px.data(), 8, 8, 8}, 2, {out.data(), 3, 4, 3}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(BinGray({px.data(), 8, 8, 8}, 0, {out.data(), 8, 8, 8}).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(BinGray({px.data(), 8, 8, 8}, kMaxBinFactor + 1, {out.data(), 1, 1, 1}).code(),
            StatusCode::kInvalidArgument);
  // A factor larger than the image leaves no whole block.
  EXPECT_EQ(BinGray({px.data(), 1, 1, 1}, 2, {out.data(), 0, 0, 0}).code(),
            StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace sh
