#include "recog/image/canny.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

using testing::Point2;
using testing::Polygon;

using testing::Side;
using testing::SidesOf;

struct Buffers {
  ZeroedPtr<FilterScratch> scratch = MakeWorkspace<FilterScratch>();
  ZeroedPtr<EdgeBuffers> edges = MakeWorkspace<EdgeBuffers>();
};

class CannySceneTest : public ::testing::TestWithParam<float> {};

TEST_P(CannySceneTest, EdgePixelsLieOnTheSidesWithPerpendicularGradient) {
  const std::vector<Polygon> polys = testing::TestScene(756, 581, 190.0);
  testing::SyntheticImage synth(756, 581, 40.0);
  for (const Polygon& p : polys) synth.Fill(p);
  synth.Blur(0.7);
  synth.AddNoise(2.0, 11);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  const std::vector<Side> sides = SidesOf(polys);

  Buffers b;
  CannyConfig config;
  config.sigma_px = GetParam();
  // Thresholds follow the peak gradient of the smallest step (0.8 * 190 - 40) at this scale.
  const float peak = 112.0f / (2.5066f * std::sqrt(config.sigma_px * config.sigma_px + 0.5f));
  config.low_threshold = 0.2f * peak;
  config.high_threshold = 0.4f * peak;
  EdgeMapView edges;
  CannyStats stats;
  ASSERT_TRUE(DetectEdges(img, config, *b.scratch, *b.edges, edges, &stats).ok());
  ASSERT_EQ(edges.edge.width, img.width);
  size_t count = 0, far = 0, checked = 0, bad_angle = 0;
  double max_angle_err = 0;
  std::vector<double> covered(sides.size(), 0.0);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const uint8_t e = edges.edge.at(x, y);
      ASSERT_TRUE(e == 0 || e == kEdgePixel);
      if (e == 0) continue;
      ++count;
      size_t nearest = 0;
      double d = 1e9;
      for (size_t i = 0; i < sides.size(); ++i) {
        const double di = testing::SegmentDistance({double(x), double(y)}, sides[i].a, sides[i].b);
        if (di < d) {
          d = di;
          nearest = i;
        }
      }
      // Within 1 px of a side; at the vertices, where Canny rounds the corner, within 2 px.
      double vertex_dist = 1e9;
      for (const Side& s : sides) {
        vertex_dist = std::min(vertex_dist, std::hypot(x - s.a.x, y - s.a.y));
      }
      const double tolerance = vertex_dist < 2.0 * config.sigma_px + 2.0 ? 2.0 : 1.0;
      if (d > tolerance) {
        ++far;
        std::printf("  off-side edge pixel (%d, %d), %.2f px from side %zu\n", x, y, d, nearest);
        continue;
      }
      covered[nearest] += 1.0;
      // Orientation away from the vertices, where the gradient turns.
      const Side& s = sides[nearest];
      const double da = std::hypot(x - s.a.x, y - s.a.y), db = std::hypot(x - s.b.x, y - s.b.y);
      if (std::min(da, db) < 3.0 * config.sigma_px + 3.0) continue;
      const double side_dir = std::atan2(s.b.y - s.a.y, s.b.x - s.a.x);
      const double grad = OrientationToAngleRad(edges.orientation.at(x, y));
      // Gradient perpendicular to the side: |angle difference mod pi - pi/2| small.
      double diff = std::fmod(std::fabs(grad - side_dir), M_PI);
      const double err = std::fabs(diff - M_PI / 2) * 180 / M_PI;
      max_angle_err = std::max(max_angle_err, err);
      ++checked;
      bad_angle += err > 3.0 ? 1 : 0;
    }
  }
  std::printf(
      "Canny sigma %.1f: %zu edge pixels, %zu off the sides, max orientation error %.2f "
      "deg over %zu\n",
      double(config.sigma_px), count, far, max_angle_err, checked);
  EXPECT_EQ(stats.edge_pixels, count);
  EXPECT_EQ(far, 0u);
  EXPECT_GT(checked, 1000u);
  EXPECT_EQ(bad_angle, 0u);
  // Every side is found along most of its length (pixels are ~1 per unit length).
  for (size_t i = 0; i < sides.size(); ++i) {
    const double len = std::hypot(sides[i].b.x - sides[i].a.x, sides[i].b.y - sides[i].a.y);
    EXPECT_GT(covered[i], 0.8 * len - 4 * config.sigma_px) << "side " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Scales, CannySceneTest, ::testing::Values(1.0f, 2.0f));

TEST(Canny, OrientationQuantisation) {
  EXPECT_EQ(QuantizeOrientation(0.0f), 0);
  EXPECT_EQ(QuantizeOrientation(float(M_PI)), 0);  // opposite gradients fold together
  EXPECT_EQ(QuantizeOrientation(float(M_PI / 2)), 128);
  EXPECT_EQ(QuantizeOrientation(float(-M_PI / 2)), 128);
  EXPECT_EQ(QuantizeOrientation(float(-M_PI / 4)), 192);
  for (int o = 0; o < 256; ++o) {
    EXPECT_EQ(QuantizeOrientation(OrientationToAngleRad(uint8_t(o))), o);
  }
}

TEST(Canny, HysteresisKeepsWeakPixelsOnlyWhenConnected) {
  // A step whose contrast fades along its length: with the high threshold above the faint end,
  // the faint part survives only because it is connected to the strong part.
  const int w = 120, h = 60;
  std::vector<uint8_t> px(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double contrast = 20.0 + 100.0 * (1.0 - x / double(w - 1));
      px[y * w + x] = uint8_t(y >= 30 ? 60 + contrast : 60);
    }
  }
  // A separate faint step that never reaches the high threshold.
  for (int y = 45; y < h; ++y) {
    for (int x = 0; x < 40; ++x) px[y * w + x] = uint8_t(px[y * w + x] + 8);
  }
  Buffers b;
  CannyConfig config;
  config.low_threshold = 2.0f;
  config.high_threshold = 30.0f;
  EdgeMapView edges;
  ASSERT_TRUE(
      DetectEdges(ConstGrayView{px.data(), w, h, w}, config, *b.scratch, *b.edges, edges).ok());
  // The fading step is continuous across the image (away from the borders).
  for (int x = 4; x < w - 4; ++x) {
    EXPECT_TRUE(edges.edge.at(x, 29) || edges.edge.at(x, 30)) << x;
  }
  // The separate faint step (gradient ~3 < 30, never connected) is absent.
  for (int x = 4; x < 36; ++x) {
    EXPECT_FALSE(edges.edge.at(x, 44) || edges.edge.at(x, 45)) << x;
  }
}

TEST(Canny, DegenerateAndBadInput) {
  Buffers b;
  EdgeMapView edges;
  CannyConfig config;
  std::vector<uint8_t> px(64, 9);
  for (auto [w, h] : {std::pair{1, 1}, {2, 3}, {64, 1}, {1, 64}}) {
    CannyStats stats;
    ASSERT_TRUE(
        DetectEdges(ConstGrayView{px.data(), w, h, w}, config, *b.scratch, *b.edges, edges, &stats)
            .ok());
    EXPECT_EQ(stats.edge_pixels, 0u);
    EXPECT_EQ(edges.edge.width, w);
  }
  EXPECT_EQ(DetectEdges(ConstGrayView{}, config, *b.scratch, *b.edges, edges).code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(DetectEdges(ConstGrayView{px.data(), kMaxImageWidth + 1, 1, kMaxImageWidth + 1}, config,
                        *b.scratch, *b.edges, edges)
                .code(),
            StatusCode::kOutOfRange);
  EXPECT_TRUE(edges.edge.empty());
  config.low_threshold = 5.0f;
  config.high_threshold = 4.0f;
  EXPECT_EQ(
      DetectEdges(ConstGrayView{px.data(), 8, 8, 8}, config, *b.scratch, *b.edges, edges).code(),
      StatusCode::kInvalidArgument);
}

// The edge map of the row bands equals the one from whole row-filtered planes (the gradient of
// each row from FilterRows and FilterColumnRow, then the same tracer), byte for byte, on an image
// of the board's size and at the scales in use up to the largest kernel.
TEST(CannyBands, EdgeMapEqualsTheWholePlaneOneByteForByte) {
  const int w = 1280, h = 800;
  std::vector<uint8_t> px;
  const ConstGrayView img = testing::NoisyTestScene(w, h, 3.0, 5, px);
  Buffers b;
  ZeroedPtr<EdgeBuffers> reference = MakeWorkspace<EdgeBuffers>(w, h);
  std::vector<float> smooth_x(static_cast<size_t>(w) * h), deriv_x(smooth_x.size());
  for (float sigma : {1.0f, 1.5f, 2.0f, kMaxGaussianSigmaPx}) {
    CannyConfig config;
    config.sigma_px = sigma;
    config.low_threshold = 1.0f;
    config.high_threshold = 2.5f;
    EdgeMapView edges;
    CannyStats stats;
    ASSERT_TRUE(DetectEdges(img, config, *b.scratch, *b.edges, edges, &stats).ok());

    GaussianKernel g0, g1;
    ASSERT_TRUE(MakeGaussianKernel(sigma, 0, g0).ok());
    ASSERT_TRUE(MakeGaussianKernel(sigma, 1, g1).ok());
    const ImageView<float> sx{smooth_x.data(), w, h, w}, dx{deriv_x.data(), w, h, w};
    FilterRows(img, &g0, sx, &g1, dx, nullptr, {});
    EdgeTracer tracer(config, *reference, w, h);
    std::vector<float> gx(w), gy(w);
    for (int y = 0; y < h; ++y) {
      FilterColumnRow(dx, g0, y, gx.data());
      FilterColumnRow(sx, g1, y, gy.data());
      tracer.AddRow(gx.data(), gy.data());
    }
    EdgeMapView expected;
    CannyStats expected_stats;
    tracer.Finish(expected, &expected_stats);
    EXPECT_GT(stats.edge_pixels, 1000u) << sigma;
    EXPECT_EQ(stats.edge_pixels, expected_stats.edge_pixels) << sigma;
    EXPECT_EQ(stats.nms_candidates, expected_stats.nms_candidates) << sigma;
    size_t differ = 0;
    for (int y = 0; y < h; ++y) {
      differ += std::memcmp(edges.edge.row(y), expected.edge.row(y), w) != 0;
      differ += std::memcmp(edges.orientation.row(y), expected.orientation.row(y), w) != 0;
    }
    EXPECT_EQ(differ, 0u) << "sigma " << sigma;
  }
}

// A work list too small for the strong pixels (16 entries, against about 1,000 strong pixels of a
// chain) leaves pixels to the raster sweeps; the edge map, the orientations and the counts equal
// those of a list with room for every pixel. One image of the board's size with noise (long
// chains in both directions), one with a spiral that must be followed back against the sweep.
TEST(CannyWorkList, FullListGivesTheSameEdgeMapAsAnUnboundedOne) {
  struct Case {
    int w = 0, h = 0;
    std::vector<uint8_t> px;
    ConstGrayView img;
  };
  std::vector<Case> cases(2);
  cases[0].w = 1280;
  cases[0].h = 800;
  cases[0].img = testing::NoisyTestScene(1280, 800, 3.0, 5, cases[0].px);
  // A square spiral of one bright ring: its inner turns are reached only through the outer ones.
  Case& spiral = cases[1];
  spiral.w = spiral.h = 200;
  spiral.px.assign(size_t{200} * 200, 40);
  int x0 = 10, y0 = 10, x1 = 189, y1 = 189;
  for (int turn = 0; x1 - x0 > 8; ++turn) {
    for (int x = x0; x <= x1; ++x) spiral.px[y0 * 200 + x] = spiral.px[(y0 + 1) * 200 + x] = 200;
    for (int y = y0; y <= y1; ++y) spiral.px[y * 200 + x1] = spiral.px[y * 200 + x1 - 1] = 200;
    for (int x = x0; x <= x1; ++x) spiral.px[y1 * 200 + x] = spiral.px[(y1 - 1) * 200 + x] = 200;
    for (int y = y0 + 6; y <= y1; ++y) spiral.px[y * 200 + x0] = spiral.px[y * 200 + x0 + 1] = 200;
    x0 += 6;
    y0 += 6;
    x1 -= 6;
    y1 -= 6;
  }
  spiral.img = ConstGrayView{spiral.px.data(), 200, 200, 200};

  for (const Case& c : cases) {
    const size_t pixels = static_cast<size_t>(c.w) * c.h;
    ZeroedPtr<FilterScratch> scratch = MakeWorkspace<FilterScratch>(c.w, c.h);
    ZeroedPtr<EdgeBuffers> unbounded = MakeZeroed<EdgeBuffers>();
    ZeroedPtr<EdgeBuffers> small = MakeZeroed<EdgeBuffers>();
    ASSERT_TRUE(unbounded->Init(c.w, c.h, pixels).ok());
    ASSERT_TRUE(small->Init(c.w, c.h, 16).ok());
    EXPECT_EQ(unbounded->stack_capacity, pixels);
    EXPECT_EQ(small->stack_capacity, 16u);
    CannyConfig config;
    config.low_threshold = 1.0f;
    config.high_threshold = 2.5f;
    EdgeMapView expected, edges;
    CannyStats expected_stats, stats;
    ASSERT_TRUE(DetectEdges(c.img, config, *scratch, *unbounded, expected, &expected_stats).ok());
    ASSERT_TRUE(DetectEdges(c.img, config, *scratch, *small, edges, &stats).ok());
    EXPECT_EQ(expected_stats.hysteresis_sweeps, 0u) << c.w;
    EXPECT_GE(stats.hysteresis_sweeps, 1u) << c.w;
    EXPECT_GT(expected_stats.edge_pixels, 500u) << c.w;
    EXPECT_EQ(stats.edge_pixels, expected_stats.edge_pixels) << c.w;
    EXPECT_EQ(stats.nms_candidates, expected_stats.nms_candidates) << c.w;
    size_t differ = 0, counted = 0;
    for (int y = 0; y < c.h; ++y) {
      differ += std::memcmp(edges.edge.row(y), expected.edge.row(y), c.w) != 0;
      differ += std::memcmp(edges.orientation.row(y), expected.orientation.row(y), c.w) != 0;
      for (int x = 0; x < c.w; ++x) counted += edges.edge.at(x, y) == kEdgePixel;
    }
    EXPECT_EQ(differ, 0u) << c.w;
    EXPECT_EQ(counted, stats.edge_pixels) << c.w;
  }
}

// The default list is kCannyWorkListCapacity entries, never more than the image's pixels.
TEST(CannyWorkList, CapacityIsTheConstantOrThePixelCount) {
  ZeroedPtr<EdgeBuffers> board = MakeWorkspace<EdgeBuffers>(1280, 800);
  ZeroedPtr<EdgeBuffers> tiny = MakeWorkspace<EdgeBuffers>(40, 30);
  ASSERT_NE(board, nullptr);
  ASSERT_NE(tiny, nullptr);
  EXPECT_EQ(board->stack_capacity, kCannyWorkListCapacity);
  EXPECT_EQ(tiny->stack_capacity, 40u * 30u);
  EXPECT_EQ(EdgeBuffers::BytesFor(1280, 800) - EdgeBuffers::BytesFor(1280, 800, 16),
            InitBlock::PieceBytes<uint32_t>(kCannyWorkListCapacity) -
                InitBlock::PieceBytes<uint32_t>(16));
}

}  // namespace
}  // namespace sh
