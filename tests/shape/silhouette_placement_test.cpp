// Placing a silhouette in a blob that merges two parts: the shift that puts it on the part it
// fits (not at the blob's centroid), pixels hidden by a part in front counting as fitting, and
// the refusal of an empty silhouette.
#include "recog/shape/silhouette_placement.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace sh {
namespace {

constexpr int kW = 200, kH = 120;

void Fill(std::vector<uint8_t>& image, int x0, int y0, int x1, int y1, uint8_t v) {
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) image[static_cast<size_t>(y) * kW + x] = v;
  }
}

// A 41 x 41 square silhouette whose box starts at (x0, y0).
struct Square {
  std::vector<uint8_t> pixels = std::vector<uint8_t>(size_t{41} * 41, 255);
  SilhouetteMask Mask(int x0, int y0) {
    SilhouetteMask m;
    m.x0 = x0;
    m.y0 = y0;
    m.width = m.height = 41;
    m.area_px = 41 * 41;
    m.cx = static_cast<float>(x0 + 20);
    m.cy = static_cast<float>(y0 + 20);
    m.mask = pixels.data();
    return m;
  }
};

TEST(SilhouettePlacement, MovesTheSilhouetteOntoThePartItFits) {
  // Blob 3: a 41 x 41 square at (30, 40) and a bar 10 px high reaching to x = 189 from it: the
  // blob's centroid lies on the bar, far right of the square.
  std::vector<uint8_t> ids(static_cast<size_t>(kW) * kH, 0);
  Fill(ids, 30, 40, 70, 80, 3);
  Fill(ids, 71, 55, 189, 64, 3);
  Fill(ids, 0, 0, 10, 10, 4);  // another blob, ignored
  const ConstGrayView view{ids.data(), kW, kH, kW};
  Square square;
  const SilhouetteMask at_centroid = square.Mask(100, 40);
  Placement placed;
  ASSERT_TRUE(PlaceSilhouette(at_centroid, view, 3, {}, {30, 40, 189, 80}, &placed));
  EXPECT_EQ(placed.dx, -70);
  EXPECT_EQ(placed.dy, 0);
  EXPECT_FLOAT_EQ(placed.overlap, 1.0f);
}

TEST(SilhouettePlacement, PixelsHiddenByAPartInFrontCountAsFitting) {
  // Blob 3: a square at (30, 40) whose lower left quarter a part in front hides, a bar, and a
  // whole square at (150, 40). Without the hidden pixels the whole square fits best; with them
  // both fit wholly and the first in scan order, the left one, wins.
  std::vector<uint8_t> ids(static_cast<size_t>(kW) * kH, 0);
  std::vector<uint8_t> hidden(static_cast<size_t>(kW) * kH, 0);
  Fill(ids, 30, 40, 70, 80, 3);
  Fill(ids, 30, 61, 49, 80, 9);  // the part in front
  Fill(hidden, 30, 61, 49, 80, 255);
  Fill(ids, 71, 55, 149, 64, 3);
  Fill(ids, 150, 40, 190, 80, 3);
  const ConstGrayView view{ids.data(), kW, kH, kW};
  Square square;
  const SilhouetteMask start = square.Mask(100, 40);
  const PixelBox box{30, 40, 190, 80};
  Placement with_hidden, without;
  ASSERT_TRUE(PlaceSilhouette(start, view, 3, {hidden.data(), kW, kH, kW}, box, &with_hidden));
  ASSERT_TRUE(PlaceSilhouette(start, view, 3, {}, box, &without));
  EXPECT_EQ(without.dx, 50);
  EXPECT_EQ(with_hidden.dx, -70);
  EXPECT_EQ(with_hidden.dy, 0);
  EXPECT_FLOAT_EQ(with_hidden.overlap, 1.0f);
}

// Hits of the silhouette sampled every `step` pixels at shift (dx, dy), each pixel counted.
uint32_t CountHits(const SilhouetteMask& s, const std::vector<uint8_t>& ids,
                   const std::vector<uint8_t>& hidden, uint8_t id, int dx, int dy, int step,
                   uint32_t* samples) {
  uint32_t hits = 0;
  *samples = 0;
  for (int y = 0; y < s.height; y += step) {
    for (int x = 0; x < s.width; x += step) {
      if (s.mask[static_cast<size_t>(y) * s.width + x] == 0) continue;
      ++*samples;
      const int ix = s.x0 + x + dx, iy = s.y0 + y + dy;
      if (ix < 0 || iy < 0 || ix >= kW || iy >= kH) continue;
      const size_t i = static_cast<size_t>(iy) * kW + ix;
      hits += ids[i] == id || hidden[i] != 0;
    }
  }
  return hits;
}

// Random blobs, silhouettes and boxes: the placement is that of counting every shift in full
// (every fourth shift with every fourth pixel, then every shift within three pixels of the best
// with every second pixel; the first of equal counts in row-major order), so the shifts the
// search gives up early change nothing.
TEST(SilhouettePlacement, IsTheBestOfEveryShiftCountedInFull) {
  std::mt19937 rng(3);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  int moved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> ids(static_cast<size_t>(kW) * kH, 0);
    std::vector<uint8_t> hidden(static_cast<size_t>(kW) * kH, 0);
    for (int k = 0; k < 6; ++k) {
      const int x0 = uniform(0, kW - 1), y0 = uniform(0, kH - 1);
      Fill(ids, x0, y0, std::min(kW - 1, x0 + uniform(0, 60)),
           std::min(kH - 1, y0 + uniform(0, 40)), static_cast<uint8_t>(k % 3 == 0 ? 4 : 3));
    }
    const int hx = uniform(0, kW - 1), hy = uniform(0, kH - 1);
    Fill(hidden, hx, hy, std::min(kW - 1, hx + 20), std::min(kH - 1, hy + 20), 255);
    // An ellipse, some of its pixels cleared.
    const int sw = uniform(5, 70), sh = uniform(5, 50);
    std::vector<uint8_t> pixels(static_cast<size_t>(sw) * sh, 0);
    for (int y = 0; y < sh; ++y) {
      for (int x = 0; x < sw; ++x) {
        const float u = (x + 0.5f) / sw - 0.5f, v = (y + 0.5f) / sh - 0.5f;
        if (u * u + v * v <= 0.25f && uniform(0, 9) != 0)
          pixels[static_cast<size_t>(y) * sw + x] = 255;
      }
    }
    SilhouetteMask s;
    s.x0 = uniform(-20, kW - 10);
    s.y0 = uniform(-20, kH - 10);
    s.width = sw;
    s.height = sh;
    s.mask = pixels.data();
    s.area_px = 1;
    const int bx = uniform(0, kW - 2), by = uniform(0, kH - 2);
    const PixelBox box{bx, by, uniform(bx + 1, kW - 1), uniform(by + 1, kH - 1)};
    const bool with_hidden = trial % 2 == 0;
    const std::vector<uint8_t> none(hidden.size(), 0);
    const std::vector<uint8_t>& counted_hidden = with_hidden ? hidden : none;
    Placement placed;
    ASSERT_TRUE(PlaceSilhouette(
        s, {ids.data(), kW, kH, kW}, 3,
        with_hidden ? ConstGrayView{hidden.data(), kW, kH, kW} : ConstGrayView{}, box, &placed));
    // The shifts that keep the silhouette in the box (the centring one when it is larger).
    auto range = [](int lo, int size, int box_lo, int box_hi, int* first, int* last) {
      *first = box_lo - lo;
      *last = box_hi - (lo + size - 1);
      if (*first > *last) {
        const int twice = (box_lo + box_hi) - (2 * lo + size - 1);
        *first = *last = twice >= 0 ? twice / 2 : -((1 - twice) / 2);
      }
    };
    int x_first, x_last, y_first, y_last;
    range(s.x0, s.width, box.x0, box.x1, &x_first, &x_last);
    range(s.y0, s.height, box.y0, box.y1, &y_first, &y_last);
    auto best = [&](int xf, int xl, int yf, int yl, int shift_step, int step, int* bdx, int* bdy,
                    uint32_t* samples) {
      bool any = false;
      uint32_t best_hits = 0;
      for (int dy = yf; dy <= yl; dy += shift_step) {
        for (int dx = xf; dx <= xl; dx += shift_step) {
          const uint32_t h = CountHits(s, ids, counted_hidden, 3, dx, dy, step, samples);
          if (!any || h > best_hits) best_hits = h, *bdx = dx, *bdy = dy, any = true;
        }
      }
      return best_hits;
    };
    int dx = 0, dy = 0;
    uint32_t samples = 0;
    best(x_first, x_last, y_first, y_last, 4, 4, &dx, &dy, &samples);
    const uint32_t hits =
        best(std::max(x_first, dx - 3), std::min(x_last, dx + 3), std::max(y_first, dy - 3),
             std::min(y_last, dy + 3), 1, 2, &dx, &dy, &samples);
    EXPECT_EQ(placed.dx, dx) << trial;
    EXPECT_EQ(placed.dy, dy) << trial;
    EXPECT_EQ(placed.overlap,
              samples ? static_cast<float>(hits) / static_cast<float>(samples) : 0.0f)
        << trial;
    moved += hits > 0 && (dx != 0 || dy != 0);
  }
  EXPECT_GT(moved, 50);  // most trials found a fit away from where the silhouette started
}

TEST(SilhouettePlacement, RefusesAnEmptySilhouette) {
  std::vector<uint8_t> ids(static_cast<size_t>(kW) * kH, 3);
  const SilhouetteMask empty;
  Placement placed;
  EXPECT_FALSE(
      PlaceSilhouette(empty, {ids.data(), kW, kH, kW}, 3, {}, {0, 0, kW - 1, kH - 1}, &placed));
}

}  // namespace
}  // namespace sh
