// Placing a silhouette in a blob that merges two parts: the shift that puts it on the part it
// fits (not at the blob's centroid), pixels hidden by a part in front counting as fitting, and
// the refusal of an empty silhouette.
#include "recog/shape/silhouette_placement.hpp"

#include <gtest/gtest.h>

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

TEST(SilhouettePlacement, RefusesAnEmptySilhouette) {
  std::vector<uint8_t> ids(static_cast<size_t>(kW) * kH, 3);
  const SilhouetteMask empty;
  Placement placed;
  EXPECT_FALSE(
      PlaceSilhouette(empty, {ids.data(), kW, kH, kW}, 3, {}, {0, 0, kW - 1, kH - 1}, &placed));
}

}  // namespace
}  // namespace sh
