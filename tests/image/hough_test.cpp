#include "recog/image/hough.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "recog/image/canny.hpp"
#include "tests/support/synthetic_image.hpp"

namespace sh {
namespace {

using testing::Point2;
using testing::Polygon;

using testing::Side;

struct Workspaces {
  ZeroedPtr<FilterScratch> scratch = MakeWorkspace<FilterScratch>();
  ZeroedPtr<EdgeBuffers> edges = MakeWorkspace<EdgeBuffers>();
  ZeroedPtr<HoughWorkspace> hough = MakeWorkspace<HoughWorkspace>();
};

ConstEdgeMapView AsConst(const EdgeMapView& e) { return {e.edge, e.orientation}; }

double AngleDiffDeg(double a, double b) {
  double d = std::fmod(std::fabs(a - b), M_PI);
  return std::min(d, M_PI - d) * 180 / M_PI;
}

// Index of the line matching a side best (smallest angle error + midpoint distance), or -1.
int MatchSide(const Vector<Line2D>& lines, const Side& s, double& angle_err, double& dist_err) {
  int best = -1;
  double best_score = 1e9;
  const double side_theta = std::atan2(s.b.y - s.a.y, s.b.x - s.a.x);
  for (size_t i = 0; i < lines.size(); ++i) {
    const Line2D& l = lines[i];
    const double ang = AngleDiffDeg(std::atan2(l.dir_y, l.dir_x), side_theta);
    const double da = std::fabs(l.DistancePx(float(s.a.x), float(s.a.y)));
    const double db = std::fabs(l.DistancePx(float(s.b.x), float(s.b.y)));
    const double score = ang + std::max(da, db);
    if (score < best_score) {
      best_score = score;
      best = int(i);
      angle_err = ang;
      dist_err =
          std::fabs(l.DistancePx(float(0.5 * (s.a.x + s.b.x)), float(0.5 * (s.a.y + s.b.y))));
    }
  }
  return best;
}

// The polygons (grey 190 on 40), blurred 0.7 px, with noise of sigma 2 (`seed`), as a grey
// image whose pixels `px` holds.
ConstGrayView TestSceneImage(int w, int h, const std::vector<Polygon>& polys, uint32_t seed,
                             std::vector<uint8_t>& px) {
  testing::SyntheticImage synth(w, h, 40.0);
  for (const Polygon& p : polys) synth.Fill(p);
  synth.Blur(0.7);
  synth.AddNoise(2.0, seed);
  return synth.ToGray(px);
}

class HoughSceneTest : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(HoughSceneTest, FindsEverySideOnceWithSubpixelAccuracy) {
  const auto [w, h] = GetParam();
  const std::vector<Polygon> polys = testing::TestScene(w, h, 190.0);
  std::vector<uint8_t> px;
  const ConstGrayView img = TestSceneImage(w, h, polys, 21, px);
  const std::vector<Side> sides = testing::SidesOf(polys);
  Workspaces ws;
  EdgeMapView edges;
  CannyConfig canny;
  ASSERT_TRUE(DetectEdges(img, canny, *ws.scratch, *ws.edges, edges).ok());
  HoughConfig config;
  Vector<Line2D, kMaxLines2d> lines;
  HoughStats stats;
  ASSERT_TRUE(DetectLines(AsConst(edges), config, *ws.hough, lines, &stats).ok());
  std::printf("%dx%d: %zu edge pixels, %zu lines, %zu peaks, %zu rejected\n", w, h,
              stats.edge_pixels, lines.size(), stats.peaks_examined, stats.lines_rejected);
  EXPECT_EQ(lines.size(), sides.size());
  std::vector<int> matched_by(lines.size(), 0);
  double worst_angle = 0, worst_dist = 0;
  for (const Side& s : sides) {
    double angle_err = 0, dist_err = 0;
    const int li = MatchSide(lines, s, angle_err, dist_err);
    ASSERT_GE(li, 0);
    ++matched_by[li];
    worst_angle = std::max(worst_angle, angle_err);
    worst_dist = std::max(worst_dist, dist_err);
    EXPECT_LT(angle_err, 0.5) << "side (" << s.a.x << "," << s.a.y << ")-(" << s.b.x << "," << s.b.y
                              << ")";
    EXPECT_LT(dist_err, 0.5);
    // The segments cover the side: inside [a, b] up to the corner rounding of Canny, and not
    // beyond its ends.
    const Line2D& l = lines[size_t(li)];
    const double ux = (s.b.x - s.a.x) / s.length(), uy = (s.b.y - s.a.y) / s.length();
    double covered = 0;
    for (const Segment2D& seg : l.segments) {
      double t0 = (seg.x0 - s.a.x) * ux + (seg.y0 - s.a.y) * uy;
      double t1 = (seg.x1 - s.a.x) * ux + (seg.y1 - s.a.y) * uy;
      if (t0 > t1) std::swap(t0, t1);
      EXPECT_GT(t0, -2.0);
      EXPECT_LT(t1, s.length() + 2.0);
      covered += std::min(t1, s.length()) - std::max(t0, 0.0);
    }
    EXPECT_GT(covered, s.length() - 8.0) << "side length " << s.length();
    if (covered < s.length() - 8.0) {
      for (const Segment2D& seg : l.segments) {
        std::printf("    seg (%.1f,%.1f)-(%.1f,%.1f) of side (%.1f,%.1f)-(%.1f,%.1f)\n", seg.x0,
                    seg.y0, seg.x1, seg.y1, s.a.x, s.a.y, s.b.x, s.b.y);
      }
    }
    EXPECT_NEAR(l.support_length_px, covered, 2.0 * l.segments.size() + 1.0);
  }
  for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(matched_by[i], 1) << "line " << i;
  std::printf("  worst angle error %.3f deg, worst distance error %.3f px\n", worst_angle,
              worst_dist);
}

INSTANTIATE_TEST_SUITE_P(Sizes, HoughSceneTest,
                         ::testing::Values(std::pair{756, 581}, std::pair{1280, 1024}));

TEST(Hough, EachEdgePixelSupportsAtMostOneLine) {
  // Crossing lines: the pixels at the crossings must go to one line only.
  const int w = 300, h = 300;
  testing::SyntheticImage synth(w, h, 30.0);
  synth.Fill({{{40, 40}, {260, 60}, {250, 70}, {35, 50}}, 200});      // thin bar
  synth.Fill({{{140, 10}, {150, 12}, {130, 290}, {120, 288}}, 200});  // crossing bar
  synth.Fill({{{20, 200}, {280, 120}, {285, 135}, {25, 215}}, 200});  // another
  std::vector<uint8_t> px;
  const ConstGrayView img = synth.ToGray(px);
  Workspaces ws;
  EdgeMapView edges;
  ASSERT_TRUE(DetectEdges(img, CannyConfig{}, *ws.scratch, *ws.edges, edges).ok());
  Vector<Line2D, kMaxLines2d> lines;
  HoughStats stats;
  ASSERT_TRUE(DetectLines(AsConst(edges), HoughConfig{}, *ws.hough, lines, &stats).ok());
  ASSERT_GE(lines.size(), 6u);
  std::vector<int> owned(lines.size(), 0);
  size_t assigned = 0;
  for (size_t i = 0; i < ws.hough->point_count; ++i) {
    const HoughEdgePoint& p = ws.hough->points[i];
    ASSERT_TRUE(edges.edge.at(p.x, p.y));
    if (p.line >= 0) {
      ASSERT_LT(size_t(p.line), lines.size());
      ++owned[size_t(p.line)];
    }
    assigned += p.line != -1 ? 1 : 0;
  }
  EXPECT_EQ(assigned, stats.edge_pixels_assigned);
  size_t total = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(owned[i], lines[i].edge_pixels) << "line " << i;
    total += size_t(lines[i].edge_pixels);
  }
  EXPECT_LE(total, stats.edge_pixels);
  // Every edge pixel appears once in the transform.
  size_t edge_count = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) edge_count += edges.edge.at(x, y) ? 1 : 0;
  }
  EXPECT_EQ(stats.edge_pixels, edge_count);
}

TEST(Hough, LineGeometryIsConsistent) {
  const int w = 200, h = 150;
  testing::SyntheticImage synth(w, h, 30.0);
  synth.Fill({{{30.2, 20.7}, {170.4, 40.1}, {150.9, 130.3}, {20.5, 110.6}}, 210});
  std::vector<uint8_t> px;
  Workspaces ws;
  EdgeMapView edges;
  ASSERT_TRUE(DetectEdges(synth.ToGray(px), CannyConfig{}, *ws.scratch, *ws.edges, edges).ok());
  Vector<Line2D, kMaxLines2d> lines;
  ASSERT_TRUE(DetectLines(AsConst(edges), HoughConfig{}, *ws.hough, lines).ok());
  ASSERT_EQ(lines.size(), 4u);
  for (const Line2D& l : lines) {
    EXPECT_GE(l.theta_rad, 0.0f);
    EXPECT_LT(l.theta_rad, float(M_PI));
    EXPECT_NEAR(std::hypot(l.dir_x, l.dir_y), 1.0, 1e-5);
    EXPECT_NEAR(l.DistancePx(l.point_x_px, l.point_y_px), 0.0, 1e-3);
    EXPECT_NEAR(l.DistancePx(l.point_x_px + 50 * l.dir_x, l.point_y_px + 50 * l.dir_y), 0.0, 1e-3);
    float sum = 0;
    for (const Segment2D& s : l.segments) {
      EXPECT_NEAR(l.DistancePx(s.x0, s.y0), 0.0, 1e-3);
      EXPECT_NEAR(l.DistancePx(s.x1, s.y1), 0.0, 1e-3);
      // Ordered along the direction.
      EXPECT_GT((s.x1 - s.x0) * l.dir_x + (s.y1 - s.y0) * l.dir_y, 0.0f);
      sum += s.length_px();
    }
    EXPECT_NEAR(sum, l.support_length_px, 1e-2);
    EXPECT_GE(l.votes, HoughConfig{}.min_votes);
    EXPECT_GE(l.edge_pixels, HoughConfig{}.min_edge_pixels);
  }
  for (size_t i = 1; i < lines.size(); ++i) EXPECT_GE(lines[i - 1].votes, lines[i].votes);
}

TEST(Hough, DashedLineGivesSeparateSegmentsAndGapsMerge) {
  const int w = 260, h = 80;
  std::vector<uint8_t> edge(static_cast<size_t>(w) * h, 0), orient(static_cast<size_t>(w) * h, 0);
  // Horizontal line y = 40 with dashes of 20 px separated by 10 px gaps; gradient along y.
  for (int x = 10; x < 250; ++x) {
    if ((x - 10) % 30 < 20) {
      edge[40 * w + x] = kEdgePixel;
      orient[40 * w + x] = 128;
    }
  }
  ConstEdgeMapView em{{edge.data(), w, h, w}, {orient.data(), w, h, w}};
  auto hough = MakeWorkspace<HoughWorkspace>();
  Vector<Line2D, kMaxLines2d> lines;
  HoughConfig config;
  ASSERT_TRUE(DetectLines(em, config, *hough, lines).ok());
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].segments.size(), 8u);
  EXPECT_NEAR(lines[0].support_length_px, 8 * 20.0f, 0.01f);
  EXPECT_NEAR(std::fabs(lines[0].DistancePx(100, 40)), 0.0f, 1e-3f);
  config.max_gap_px = 12.0f;
  ASSERT_TRUE(DetectLines(em, config, *hough, lines).ok());
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].segments.size(), 1u);
  EXPECT_NEAR(lines[0].segments[0].length_px(), 230.0f, 0.01f);
  // More dashes than a line holds: the longest kMaxSegmentsPerLine are kept.
  std::fill(edge.begin(), edge.end(), 0);
  for (int x = 2; x < 258; ++x) {
    const bool long_dash = x < 130;
    const bool on = long_dash ? (x - 2) % 12 < 8 : (x >= 132 && (x - 132) % 8 < 6);
    if (on) {
      edge[40 * w + x] = kEdgePixel;
      orient[40 * w + x] = 128;
    }
  }
  config = HoughConfig{};
  config.max_gap_px = 1.0f;
  ASSERT_TRUE(DetectLines(em, config, *hough, lines).ok());
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].segments.size(), kMaxSegmentsPerLine);
  // 11 dashes of 8 px on the left, 16 of 6 px on the right: all long ones and 5 short ones.
  int long_count = 0;
  for (const Segment2D& s : lines[0].segments) {
    const bool is_long = std::fabs(s.length_px() - 8.0f) < 0.01f;
    EXPECT_TRUE(is_long || std::fabs(s.length_px() - 6.0f) < 0.01f) << s.length_px();
    long_count += is_long ? 1 : 0;
  }
  EXPECT_EQ(long_count, 11);
  for (size_t i = 1; i < lines[0].segments.size(); ++i) {
    const Segment2D& a = lines[0].segments[i - 1];
    const Segment2D& b = lines[0].segments[i];
    EXPECT_GT((b.x0 - a.x1) * lines[0].dir_x + (b.y0 - a.y1) * lines[0].dir_y, 0.0f);
  }
}

TEST(Hough, PathologicalEdgeMapsFillBuffersWithDefinedResults) {
  // Every pixel an edge with random orientation: more pixels than the transform takes.
  const int w = kMaxImageWidth, h = kMaxImageHeight;
  std::vector<uint8_t> edge(size_t(w) * h, kEdgePixel), orient(size_t(w) * h);
  std::mt19937 rng(3);
  for (uint8_t& o : orient) o = uint8_t(rng());
  ConstEdgeMapView em{{edge.data(), w, h, w}, {orient.data(), w, h, w}};
  auto hough = MakeWorkspace<HoughWorkspace>();
  Vector<Line2D, kMaxLines2d> lines;
  HoughStats stats;
  HoughConfig config;
  config.max_peaks = 600;  // keeps the test short; the bound itself is what is tested
  ASSERT_TRUE(DetectLines(em, config, *hough, lines, &stats).ok());
  EXPECT_EQ(stats.edge_pixels, kMaxHoughEdgePixels);
  EXPECT_EQ(stats.edge_pixels_dropped, size_t(w) * h - kMaxHoughEdgePixels);
  EXPECT_TRUE(stats.stopped_by_capacity);
  EXPECT_LE(lines.size(), kMaxLines2d);
  EXPECT_LE(stats.peaks_examined, size_t(config.max_peaks));
  for (const Line2D& l : lines) EXPECT_LE(l.segments.size(), kMaxSegmentsPerLine);
  // More than kMaxLines2d strong lines (4 px apart, beyond the 2 px collection band), all within
  // the transform's capacity, fill the line output exactly: 254 rows of 200 px on the left, 270
  // columns of 400 px on the right.
  std::fill(edge.begin(), edge.end(), 0);
  const int split_x = 200, column_length = 400;
  size_t grid_pixels = 0, grid_lines = 0;
  for (int y = 2; y < h - 2; y += 4, ++grid_lines) {
    for (int x = 0; x < split_x; ++x, ++grid_pixels) {
      edge[size_t(y) * w + x] = kEdgePixel;
      orient[size_t(y) * w + x] = 128;
    }
  }
  for (int x = split_x + 2; x < w - 2; x += 4, ++grid_lines) {
    for (int y = 0; y < column_length; ++y, ++grid_pixels) {
      edge[size_t(y) * w + x] = kEdgePixel;
      orient[size_t(y) * w + x] = 0;
    }
  }
  ASSERT_GT(grid_lines, kMaxLines2d);
  ASSERT_LE(grid_pixels, kMaxHoughEdgePixels);
  ASSERT_TRUE(DetectLines(em, HoughConfig{}, *hough, lines, &stats).ok());
  EXPECT_EQ(stats.edge_pixels_dropped, 0u);
  EXPECT_EQ(lines.size(), kMaxLines2d);
  EXPECT_TRUE(stats.stopped_by_capacity);
}

TEST(Hough, EmptyAndBadInput) {
  auto hough = MakeWorkspace<HoughWorkspace>();
  Vector<Line2D, kMaxLines2d> lines;
  std::vector<uint8_t> zero(64, 0);
  ConstEdgeMapView em{{zero.data(), 8, 8, 8}, {zero.data(), 8, 8, 8}};
  ASSERT_TRUE(DetectLines(em, HoughConfig{}, *hough, lines).ok());
  EXPECT_TRUE(lines.empty());
  EXPECT_EQ(DetectLines(ConstEdgeMapView{}, HoughConfig{}, *hough, lines).code(),
            StatusCode::kInvalidArgument);
  ConstEdgeMapView mismatched{{zero.data(), 8, 8, 8}, {zero.data(), 4, 8, 4}};
  EXPECT_EQ(DetectLines(mismatched, HoughConfig{}, *hough, lines).code(),
            StatusCode::kInvalidArgument);
  ConstEdgeMapView big{{zero.data(), kMaxImageWidth + 1, 1, kMaxImageWidth + 1},
                       {zero.data(), kMaxImageWidth + 1, 1, kMaxImageWidth + 1}};
  EXPECT_EQ(DetectLines(big, HoughConfig{}, *hough, lines).code(), StatusCode::kOutOfRange);
  HoughConfig bad;
  bad.vote_half_width_px = 9.0f;
  EXPECT_EQ(DetectLines(em, bad, *hough, lines).code(), StatusCode::kOutOfRange);
  bad = HoughConfig{};
  bad.collect_distance_px = 0.0f;
  EXPECT_EQ(DetectLines(em, bad, *hough, lines).code(), StatusCode::kInvalidArgument);
}

// Pixel lists carved from memory the caller lends: too little of it is refused with both sizes.
TEST(Hough, BorrowedScratchMustHoldBothPixelLists) {
  const int w = 64, h = 48;
  auto ws = MakeZeroed<HoughWorkspace>();
  ASSERT_NE(ws, nullptr);
  std::vector<uint8_t> scratch(HoughWorkspace::ScratchBytesFor(w, h));
  const Status small = ws->Init(w, h, scratch.data(), scratch.size() - 1);
  EXPECT_EQ(small.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(std::strstr(small.message(), "64x48"), nullptr) << small.message();
  ASSERT_TRUE(ws->Init(w, h, scratch.data(), scratch.size()).ok());
  const auto* first = reinterpret_cast<const uint8_t*>(ws->collected);
  const auto* last = reinterpret_cast<const uint8_t*>(ws->subset + ws->point_capacity());
  EXPECT_GE(first, scratch.data());
  EXPECT_LE(last, scratch.data() + scratch.size());
  EXPECT_GE(reinterpret_cast<const uint8_t*>(ws->subset),
            reinterpret_cast<const uint8_t*>(ws->collected + ws->point_capacity()));
}

// The accumulator is sized at Init for the workspace's image size, its bin of rho 0 lowered by
// whole blocks: a 1280 x 800 workspace takes fewer bins than one of the maximum size and finds
// the same lines, to the bit, on the same edges.
TEST(Hough, AccumulatorSizedForTheWorkspaceFindsTheSameLines) {
  const int w = 1280, h = 800;
  std::vector<uint8_t> px;
  const ConstGrayView img = TestSceneImage(w, h, testing::TestScene(w, h, 190.0), 23, px);
  Workspaces full;
  EdgeMapView edges;
  ASSERT_TRUE(DetectEdges(img, CannyConfig{}, *full.scratch, *full.edges, edges).ok());
  auto sized = MakeWorkspace<HoughWorkspace>(w, h);
  ASSERT_NE(sized, nullptr);
  EXPECT_LT(sized->acc_stride, full.hough->acc_stride);
  EXPECT_LT(sized->rho_offset, full.hough->rho_offset);
  EXPECT_LT(HoughWorkspace::OwnBytesFor(w, h),
            HoughWorkspace::OwnBytesFor(kMaxImageWidth, kMaxImageHeight));
  Vector<Line2D, kMaxLines2d> a;
  Vector<Line2D, kMaxLines2d> b;
  HoughStats sa;
  HoughStats sb;
  ASSERT_TRUE(DetectLines(AsConst(edges), HoughConfig{}, *sized, a, &sa).ok());
  ASSERT_TRUE(DetectLines(AsConst(edges), HoughConfig{}, *full.hough, b, &sb).ok());
  ASSERT_GT(a.size(), 3u);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(sa.peaks_examined, sb.peaks_examined);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].theta_rad, b[i].theta_rad) << i;
    EXPECT_EQ(a[i].rho_px, b[i].rho_px) << i;
    EXPECT_EQ(a[i].votes, b[i].votes) << i;
    EXPECT_EQ(a[i].edge_pixels, b[i].edge_pixels) << i;
  }
}

}  // namespace
}  // namespace sh
