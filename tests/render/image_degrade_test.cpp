// The degradation `stereohash bench recorded --noise/--blur/--gain` applies to recorded images:
// the noise it adds has the standard deviation asked for (and the front end's estimator measures
// it), the same seed gives the same bytes, exposure clips at white, defocus keeps the mean.
#include "tools/eval/image_degrade.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "recog/image/noise.hpp"

namespace sh::tools {
namespace {

constexpr int kW = 200, kH = 150;

std::vector<uint8_t> Flat(uint8_t grey, int channels = 1) {
  return std::vector<uint8_t>(size_t(kW) * kH * channels, grey);
}

struct Moments {
  double mean = 0, sd = 0;
};
Moments MomentsOf(const std::vector<uint8_t>& p, int channels = 1, int channel = 0) {
  double sum = 0, sum2 = 0;
  const size_t n = p.size() / channels;
  for (size_t i = 0; i < n; ++i) {
    const double v = p[i * channels + channel];
    sum += v;
    sum2 += v * v;
  }
  Moments m;
  m.mean = sum / n;
  m.sd = std::sqrt(sum2 / n - m.mean * m.mean);
  return m;
}

TEST(ImageDegrade, NothingAskedChangesNothing) {
  std::vector<uint8_t> image = Flat(90);
  image[17] = 3;
  const std::vector<uint8_t> before = image;
  ASSERT_TRUE(DegradeImage(ImageDegradation{}, 1, kW, kH, 1, image.data()).ok());
  EXPECT_EQ(image, before);
}

// Half read, half shot noise: sigma at mid grey, less on dark pixels (sigma^2 (1/2 + I/256)).
TEST(ImageDegrade, NoiseHasTheStandardDeviationAskedForAtMidGrey) {
  for (const float sigma : {2.0f, 6.0f}) {
    ImageDegradation d;
    d.noise_sigma = sigma;
    std::vector<uint8_t> mid = Flat(128), dark = Flat(32);
    ASSERT_TRUE(DegradeImage(d, 7, kW, kH, 1, mid.data()).ok());
    ASSERT_TRUE(DegradeImage(d, 7, kW, kH, 1, dark.data()).ok());
    const Moments m = MomentsOf(mid), k = MomentsOf(dark);
    EXPECT_NEAR(m.mean, 128.0, 0.1);
    EXPECT_NEAR(m.sd, sigma, 0.05 * sigma);
    EXPECT_NEAR(k.sd, sigma * std::sqrt(0.5 + 32.0 / 256.0), 0.05 * sigma);
    // The front end's noise estimate (which sets its thresholds) sees the same sigma.
    const NoiseEstimate e = EstimateNoise(ConstGrayView{mid.data(), kW, kH, kW});
    EXPECT_NEAR(e.sigma, sigma, 0.1 * sigma);
  }
}

TEST(ImageDegrade, TheSameSeedGivesTheSameBytesAndEachChannelItsOwnNoise) {
  ImageDegradation d;
  d.noise_sigma = 4.0f;
  std::vector<uint8_t> a = Flat(100, 3), b = Flat(100, 3), c = Flat(100, 3);
  ASSERT_TRUE(DegradeImage(d, 42, kW, kH, 3, a.data()).ok());
  ASSERT_TRUE(DegradeImage(d, 42, kW, kH, 3, b.data()).ok());
  ASSERT_TRUE(DegradeImage(d, 43, kW, kH, 3, c.data()).ok());
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  size_t same_rg = 0;
  for (size_t i = 0; i < a.size(); i += 3) same_rg += a[i] == a[i + 1];
  EXPECT_LT(same_rg, a.size() / 3 / 4);  // independent draws agree on about a tenth
  EXPECT_NE(DegradationSeed("scene00", 0), DegradationSeed("scene00", 1));
  EXPECT_NE(DegradationSeed("scene00", 0), DegradationSeed("scene01", 0));
  EXPECT_EQ(DegradationSeed("scene07", 1), DegradationSeed("scene07", 1));
}

TEST(ImageDegrade, GainScalesAndClipsAtWhite) {
  ImageDegradation d;
  d.gain = 1.5f;
  std::vector<uint8_t> image = {100, 200, 0, 170};
  ASSERT_TRUE(DegradeImage(d, 1, 4, 1, 1, image.data()).ok());
  EXPECT_EQ(image, (std::vector<uint8_t>{150, 255, 0, 255}));
}

TEST(ImageDegrade, DefocusSpreadsAStepAndKeepsTheMean) {
  ImageDegradation d;
  d.blur_sigma_px = 2.0f;
  std::vector<uint8_t> image(size_t(kW) * kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) image[size_t(y) * kW + x] = x < kW / 2 ? 40 : 200;
  }
  const double mean_before = MomentsOf(image).mean;
  ASSERT_TRUE(DegradeImage(d, 1, kW, kH, 1, image.data()).ok());
  const uint8_t* row = &image[size_t(kH / 2) * kW];
  EXPECT_EQ(row[10], 40);
  EXPECT_EQ(row[kW - 10], 200);
  EXPECT_GT(row[kW / 2 - 1], 40 + 20);  // within a sigma of the step: in between
  EXPECT_LT(row[kW / 2], 200 - 20);
  EXPECT_NEAR(MomentsOf(image).mean, mean_before, 0.5);
}

TEST(ImageDegrade, OutOfRangeSettingsAreRefusedByName) {
  uint8_t pixel = 0;
  ImageDegradation noise, blur, gain;
  noise.noise_sigma = -1.0f;
  blur.blur_sigma_px = 0.1f;
  gain.gain = 0.0f;
  for (const auto& [d, word] : {std::pair{noise, "noise"}, {blur, "blur"}, {gain, "gain"}}) {
    const Status s = DegradeImage(d, 1, 1, 1, 1, &pixel);
    EXPECT_FALSE(s.ok()) << word;
    EXPECT_NE(std::strstr(s.message(), word), nullptr) << s.message();
  }
  ImageDegradation ok;
  ok.noise_sigma = 1.0f;
  EXPECT_FALSE(DegradeImage(ok, 1, 0, 5, 1, &pixel).ok());
  EXPECT_FALSE(DegradeImage(ok, 1, 1, 1, 1, nullptr).ok());
}

}  // namespace
}  // namespace sh::tools
