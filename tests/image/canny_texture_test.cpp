// Canny thresholds that rise over texture (CannyConfig::texture_factor), with the thresholds the
// automatic preset takes from the noise.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "recog/image/canny.hpp"
#include "recog/image/features.hpp"
#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

using testing::Polygon;
using testing::Side;

// The detection of the automatic presets (FeatureConfig::Automatic), edges only.
FeatureConfig Automatic(float texture_factor) {
  FeatureConfig c = FeatureConfig::Automatic();
  c.canny.texture_factor = texture_factor;
  c.detect_corners = false;
  return c;
}

struct Extracted {
  std::unique_ptr<ImageFeatures> features = std::make_unique<ImageFeatures>();
  std::vector<uint8_t> edge, orientation;
};

Extracted Extract(const ConstGrayView& img, const FeatureConfig& config) {
  static ZeroedPtr<FeatureWorkspace> ws = MakeWorkspace<FeatureWorkspace>();
  Extracted out;
  const Status s = ExtractFeatures(img, config, *ws, *out.features);
  EXPECT_TRUE(s.ok()) << s.message();
  const EdgeMapView& e = out.features->edges;
  for (int y = 0; y < e.edge.height; ++y) {
    out.edge.insert(out.edge.end(), e.edge.row(y), e.edge.row(y) + e.edge.width);
    const uint8_t* o = e.orientation.row(y);
    out.orientation.insert(out.orientation.end(), o, o + e.orientation.width);
  }
  return out;
}

// Where the texture is no stronger than the sensor noise (a plain table, objects' faces), the
// edge map is byte for byte that without the test, at low and high noise and at sizes that end
// in part blocks.
TEST(CannyTexture, APlainNoisyImageGivesTheEdgeMapWithoutTheTest) {
  struct Size {
    int w, h;
  };
  for (const Size size : {Size{756, 581}, Size{1281, 97}}) {
    for (double noise : {1.0, 6.0}) {
      std::vector<uint8_t> px;
      const ConstGrayView img = testing::NoisyTestScene(size.w, size.h, noise, 7, px);
      const Extracted off = Extract(img, Automatic(0.0f));
      const Extracted on = Extract(img, Automatic(3.0f));
      const CannyStats& stats = on.features->canny_stats;
      EXPECT_GT(off.features->canny_stats.edge_pixels, 200u) << size.w << " " << noise;
      EXPECT_EQ(stats.textured_blocks, 0u) << size.w << " " << noise;
      // Partial blocks at the right and bottom borders count.
      EXPECT_EQ(stats.texture_blocks, size_t((size.w + 31) / 32) * size_t((size.h + 31) / 32))
          << size.w;
      EXPECT_EQ(off.features->canny_stats.texture_blocks, 0u) << size.w;
      EXPECT_EQ(on.features->chosen.texture_blocks, stats.texture_blocks) << size.w;
      EXPECT_EQ(stats.texture_dropped, 0u) << size.w << " " << noise;
      EXPECT_TRUE(off.edge == on.edge) << size.w << " " << noise;
      EXPECT_TRUE(off.orientation == on.orientation) << size.w << " " << noise;
      EXPECT_EQ(off.features->lines.size(), on.features->lines.size()) << size.w << " " << noise;
    }
  }
}

// Light objects on a dark mottled table, at a noise level whose thresholds let every ripple of
// the mottle through: the texture's edge pixels and lines go, the outlines stay.
TEST(CannyTexture, AMottledTableLosesItsEdgesAndTheObjectsKeepTheirOutlines) {
  // The test scene at half size in the middle: a table around the objects, as a camera sees it.
  const int w = 756, h = 581;
  std::vector<Polygon> polys = testing::TestScene(w / 2, h / 2, 150.0);
  for (Polygon& p : polys) {
    for (testing::Point2& v : p.vertices) v = {v.x + w / 4.0, v.y + h / 4.0};
  }
  testing::SyntheticImage synth(w, h, 50.0);
  synth.AddMottle(6.0, 3.0, 21);
  for (const Polygon& p : polys) synth.Fill(p);
  synth.Blur(0.7);
  synth.AddNoise(1.5, 22);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  const std::vector<Side> sides = testing::SidesOf(polys);

  // Edge pixels within 1.5 px of a side (the outlines), beyond 4 px of every side (texture), and
  // beyond two blocks of every side (the open table, where every block around is textured).
  struct Count {
    size_t near = 0, far = 0, open = 0;
  };
  auto count = [&](const Extracted& e) {
    Count c;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        if (e.edge[static_cast<size_t>(y) * w + x] == 0) continue;
        double d = std::numeric_limits<double>::infinity();
        for (const Side& s : sides)
          d = std::fmin(d, testing::SegmentDistance({x + 0.0, y + 0.0}, s.a, s.b));
        c.near += d <= 1.5;
        c.far += d > 4.0;
        c.open += d > 2 * kTextureBlockPx;
      }
    }
    return c;
  };
  const Extracted off = Extract(img, Automatic(0.0f));
  const Extracted on = Extract(img, Automatic(3.0f));
  const Count a = count(off), b = count(on);
  double outline = 0;
  for (const Side& s : sides) outline += s.length();
  // Without the test the mottle floods the map and fills the line list.
  EXPECT_GT(a.open, 20000u);
  EXPECT_GT(off.features->lines.size(), 300u);
  EXPECT_GT(a.near, 0.9 * outline);
  // With it, the open table keeps at most a fifth of them, and the texture beside the objects
  // (whose blocks see the flat faces) a part; the outlines keep nearly every pixel and the line
  // list comes down to the order of the sides.
  EXPECT_LT(b.open, a.open / 5);
  EXPECT_LT(b.far, a.far / 3);
  EXPECT_GE(b.near, 0.97 * a.near);
  EXPECT_LT(on.features->lines.size(), off.features->lines.size() / 4);
  EXPECT_GE(on.features->lines.size(), sides.size() - 2);
  const CannyStats& stats = on.features->canny_stats;
  EXPECT_GT(stats.textured_blocks, 200u);  // of 24 x 19
  EXPECT_GT(stats.texture_dropped, 10000u);
}

// A patch of fine detail no larger than two blocks (a part's ribs, a cluster of parts) raises its
// own blocks' quartiles, but their neighbours see the plain table around it: its weak edges stay.
TEST(CannyTexture, DetailWithinTwoBlocksOfAPlainSurfaceIsNotTexture) {
  const int w = 320, h = 240;
  testing::SyntheticImage synth(w, h, 60.0);
  // Bars 4 px wide of contrast 15 over 64 x 64 px.
  for (int i = 0; i < 8; ++i) {
    const double x0 = 128.3 + 8 * i;
    synth.Fill({{{x0, 88.6}, {x0 + 4, 88.6}, {x0 + 4, 152.6}, {x0, 152.6}}, 75.0});
  }
  synth.Blur(0.7);
  synth.AddNoise(1.0, 5);
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  const Extracted off = Extract(img, Automatic(0.0f));
  const Extracted on = Extract(img, Automatic(3.0f));
  EXPECT_GT(off.features->canny_stats.edge_pixels, 800u);
  EXPECT_EQ(on.features->canny_stats.texture_dropped, 0u);
  EXPECT_TRUE(off.edge == on.edge);
}

TEST(CannyTexture, FactorsOutsideTheRangeAreRefusedByName) {
  for (float factor : {-1.0f, 65.0f, std::numeric_limits<float>::quiet_NaN()}) {
    CannyConfig config;
    config.texture_factor = factor;
    const Status s = ValidateCannyConfig(config);
    EXPECT_EQ(s.code(), StatusCode::kOutOfRange) << factor;
    EXPECT_NE(std::strstr(s.message(), "texture factor"), nullptr) << s.message();
  }
}

}  // namespace
}  // namespace sh
