#include "recog/image/gaussian.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

// Whole float planes of the largest image, for the filters' plane interface.
struct TestPlanes {
  std::vector<float> store[3];
  FloatPlane planes[3];
  TestPlanes() {
    for (int i = 0; i < 3; ++i) {
      store[i].assign(kMaxImagePixels, 0.0f);
      planes[i].data = store[i].data();
    }
  }
};

// Kernel built independently in double precision from the same definition.
std::vector<double> ReferenceKernel(double sigma, int order, int r) {
  std::vector<double> g(2 * r + 1), h(2 * r + 1);
  double sum = 0;
  for (int k = -r; k <= r; ++k) sum += g[k + r] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (double& v : g) v /= sum;
  if (order == 0) return g;
  if (order == 1) {
    double m = 0;
    for (int k = -r; k <= r; ++k) m += k * (h[k + r] = k * g[k + r]);
    for (double& v : h) v /= m;
    return h;
  }
  double dc = 0;
  for (int k = -r; k <= r; ++k) dc += h[k + r] = (k * k / (sigma * sigma) - 1) * g[k + r];
  double m = 0;
  for (int k = -r; k <= r; ++k) m += 0.5 * k * k * (h[k + r] -= dc * g[k + r]);
  for (double& v : h) v /= m;
  return h;
}

// Direct 2-D double-precision correlation with replicated borders.
std::vector<double> ReferenceFilter(const ConstGrayView& img, double sigma, int ox, int oy) {
  const int r = GaussianRadiusFor(float(sigma));
  const std::vector<double> kx = ReferenceKernel(sigma, ox, r), ky = ReferenceKernel(sigma, oy, r);
  std::vector<double> out(size_t(img.width) * img.height);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      double a = 0;
      for (int j = -r; j <= r; ++j) {
        const int yy = std::clamp(y + j, 0, img.height - 1);
        for (int i = -r; i <= r; ++i) {
          a += ky[j + r] * kx[i + r] * img.at(std::clamp(x + i, 0, img.width - 1), yy);
        }
      }
      out[size_t(y) * img.width + x] = a;
    }
  }
  return out;
}

TEST(GaussianKernel, MomentsMakeTheFilterExactOnPolynomials) {
  for (float sigma : {0.5f, 1.0f, 2.0f, 6.0f, 8.0f}) {
    for (int order = 0; order <= 2; ++order) {
      GaussianKernel k;
      ASSERT_TRUE(MakeGaussianKernel(sigma, order, k).ok());
      EXPECT_EQ(k.radius, GaussianRadiusFor(sigma));
      double m0 = 0, m1 = 0, m2 = 0;
      for (int i = -k.radius; i <= k.radius; ++i) {
        const double t = (order == 1 && i < 0) ? -k.taps[-i] : k.taps[std::abs(i)];
        m0 += t;
        m1 += i * t;
        m2 += 0.5 * i * i * t;
      }
      EXPECT_NEAR(m0, order == 0 ? 1.0 : 0.0, 1e-5) << sigma << " " << order;
      EXPECT_NEAR(m1, order == 1 ? 1.0 : 0.0, 1e-5) << sigma << " " << order;
      if (order == 2) {
        EXPECT_NEAR(m2, 1.0, 1e-5) << sigma;
      }
    }
  }
}

TEST(GaussianKernel, RejectsBadSigmaAndOrder) {
  GaussianKernel k;
  EXPECT_EQ(MakeGaussianKernel(0.0f, 0, k).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(MakeGaussianKernel(kMaxGaussianSigmaPx * 1.01f, 0, k).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(MakeGaussianKernel(NAN, 0, k).code(), StatusCode::kOutOfRange);
  EXPECT_EQ(MakeGaussianKernel(1.0f, 3, k).code(), StatusCode::kInvalidArgument);
  EXPECT_LE(GaussianRadiusFor(kMaxGaussianSigmaPx), kMaxGaussianRadius);
}

TEST(GaussianFilter, MatchesDoublePrecisionReference) {
  testing::SyntheticImage synth(97, 83, 40.0);
  for (const testing::Polygon& p : testing::TestScene(97, 83, 210.0)) synth.Fill(p);
  synth.AddNoise(8.0, 7);
  std::vector<uint8_t> pixels;
  const ConstGrayView img = synth.ToGray(pixels);
  auto scratch = std::make_unique<TestPlanes>();
  for (float sigma : {1.0f, 2.0f, 6.0f}) {
    for (auto [ox, oy] : {std::pair{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}}) {
      ImageView<float> out = scratch->planes[1].view(img.width, img.height);
      ASSERT_TRUE(GaussianFilter2d(img, sigma, ox, oy, scratch->planes[0], out).ok());
      const std::vector<double> ref = ReferenceFilter(img, sigma, ox, oy);
      double max_err = 0, max_ref = 0;
      for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
          const double r = ref[size_t(y) * img.width + x];
          max_err = std::max(max_err, std::fabs(out.at(x, y) - r));
          max_ref = std::max(max_ref, std::fabs(r));
        }
      }
      std::printf("sigma %.0f d/dx^%d d/dy^%d: max |float - double| %.2e (max |value| %.1f)\n",
                  double(sigma), ox, oy, max_err, max_ref);
      // Float keeps ~7 significant digits; taps x 255 grey levels stay far above that.
      EXPECT_LT(max_err, 1e-4 * std::max(1.0, max_ref) + 1e-4);
    }
  }
}

TEST(GaussianFilter, DerivativesOfASinusoidFollowTheAnalyticResponse) {
  // I = 128 + 100 sin(w x): Gaussian smoothing multiplies the amplitude by exp(-w^2 sigma^2 / 2).
  const int w = 200, h = 8;
  const double freq = 2 * M_PI / 40.0;
  std::vector<uint8_t> px(static_cast<size_t>(w) * h);
  std::vector<double> exact(w);
  for (int x = 0; x < w; ++x) exact[x] = 128 + 100 * std::sin(freq * x);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) px[y * w + x] = uint8_t(std::lround(exact[x]));
  }
  const ConstGrayView img{px.data(), w, h, w};
  auto scratch = std::make_unique<TestPlanes>();
  const float sigma = 2.0f;
  const double atten = std::exp(-0.5 * freq * freq * sigma * sigma);
  ImageView<float> dx = scratch->planes[1].view(w, h);
  ASSERT_TRUE(GaussianFilter2d(img, sigma, 1, 0, scratch->planes[0], dx).ok());
  ImageView<float> dxx = scratch->planes[2].view(w, h);
  ASSERT_TRUE(GaussianFilter2d(img, sigma, 2, 0, scratch->planes[0], dxx).ok());
  // 8-bit rounding of the input is an error of at most 0.5 grey level per pixel, so a filter can
  // be off by 0.5 * sum |taps|, plus a small sampling error of the kernel.
  auto rounding_bound = [](float s, int order) {
    GaussianKernel k;
    EXPECT_TRUE(MakeGaussianKernel(s, order, k).ok());
    double sum = std::fabs(k.taps[0]);
    for (int i = 1; i <= k.radius; ++i) sum += 2 * std::fabs(k.taps[i]);
    return 0.5 * sum;
  };
  const double bound_dx = rounding_bound(sigma, 1) + 0.01 * 100 * freq;
  const double bound_dxx = rounding_bound(sigma, 2) + 0.01 * 100 * freq * freq;
  for (int x = 20; x < w - 20; ++x) {
    EXPECT_NEAR(dx.at(x, 4), 100 * freq * atten * std::cos(freq * x), bound_dx) << x;
    EXPECT_NEAR(dxx.at(x, 4), -100 * freq * freq * atten * std::sin(freq * x), bound_dxx) << x;
  }
}

TEST(RowBand, ColumnPassesEqualTheWholePlanesBitForBit) {
  // 1280 x 800 (the board's size), and images lower than a kernel (rows clamped at both ends).
  for (auto [w, h] : {std::pair{1280, 800}, {1280, 9}, {64, 1}}) {
    std::vector<uint8_t> pixels;
    const ConstGrayView img = testing::NoisyTestScene(w, h, 6.0, 3, pixels);
    ZeroedPtr<FilterScratch> scratch = MakeWorkspace<FilterScratch>(w, h);
    ASSERT_NE(scratch, nullptr);
    auto whole = std::make_unique<TestPlanes>();
    // Up to the largest radius (sigma 8 px: 24 rows each side, the ring's whole height).
    for (float sigma : {0.3f, 1.0f, 1.5f, 2.0f, 6.0f, kMaxGaussianSigmaPx}) {
      GaussianKernel k[3];
      for (int order = 0; order < 3; ++order) {
        ASSERT_TRUE(MakeGaussianKernel(sigma, order, k[order]).ok());
      }
      ImageView<float> rows[3];
      for (int i = 0; i < 3; ++i) rows[i] = whole->planes[i].view(w, h);
      FilterRows(img, &k[0], rows[0], &k[1], rows[1], &k[2], rows[2]);
      RowBand band(img, *scratch, &k[0], &k[1], &k[2]);
      std::vector<float> expected(w), got(w);
      const float* ptrs[2 * kMaxGaussianRadius + 1];
      size_t mismatches = 0;
      for (int y = 0; y < h; ++y) {
        band.FillTo(y + k[0].radius);
        for (int ring = 0; ring < 3; ++ring) {
          for (int order = 0; order < 3; ++order) {
            FilterColumnRow(rows[ring], k[order], y, expected.data());
            band.RowPointers(ring, y, k[order].radius, ptrs);
            FilterColumnRowFrom(ptrs, k[order], w, got.data());
            mismatches += std::memcmp(expected.data(), got.data(), sizeof(float) * w) != 0;
          }
        }
      }
      EXPECT_EQ(mismatches, 0u) << w << "x" << h << " sigma " << sigma;
    }
  }
}

TEST(GaussianFilter, RefusesBadImages) {
  auto scratch = std::make_unique<TestPlanes>();
  std::vector<uint8_t> px(16, 0);
  ImageView<float> out = scratch->planes[1].view(4, 4);
  EXPECT_EQ(
      GaussianFilter2d(ConstGrayView{nullptr, 4, 4, 4}, 1.0f, 0, 0, scratch->planes[0], out).code(),
      StatusCode::kInvalidArgument);
  EXPECT_EQ(GaussianFilter2d(ConstGrayView{px.data(), 4, 4, 3}, 1.0f, 0, 0, scratch->planes[0], out)
                .code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(GaussianFilter2d(ConstGrayView{px.data(), kMaxImageWidth + 1, 1, kMaxImageWidth + 1},
                             1.0f, 0, 0, scratch->planes[0], out)
                .code(),
            StatusCode::kOutOfRange);
  // A single pixel is a valid image: every filter sees a constant.
  ImageView<float> one = scratch->planes[1].view(1, 1);
  px[0] = 77;
  ASSERT_TRUE(
      GaussianFilter2d(ConstGrayView{px.data(), 1, 1, 1}, 2.0f, 0, 0, scratch->planes[0], one)
          .ok());
  EXPECT_NEAR(one.at(0, 0), 77.0f, 1e-3);
}

}  // namespace
}  // namespace sh
