// Parts of a mask: its connected components, and a split at narrow necks, for regions that are
// two touching parts of one colour.
//
// The split is a watershed of the distance transform with a persistence rule: pixels are added
// in order of decreasing distance to the mask's border, so every part grows from its own
// distance peak (the centre of its largest inscribed disc); where two growing parts meet, they
// stay apart if the meeting point's distance (half the neck's width) is below `neck_ratio` times
// the smaller peak, else they merge. Thin protrusions of one part (a star's arms, a bracket's
// legs) have no peak of their own and never split off; two convex parts touching along less
// than their own width do.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/image/image.hpp"

namespace sh {

// Largest mask (bounding box pixels) the scratch is sized for; larger masks are not split.
inline constexpr size_t kMaxSplitPixels = size_t{512} * 512;
inline constexpr int kMaxMaskParts = 16;

struct MaskPartsScratch {
  uint16_t distance[kMaxSplitPixels];  // chamfer 3-4: 3 per pixel step
  uint32_t order[kMaxSplitPixels];
  uint32_t parent[kMaxSplitPixels];
  uint32_t area[kMaxSplitPixels];
  uint16_t peak[kMaxSplitPixels];
  uint32_t count[3 * 1024 + 2];
};

struct MaskPart {
  uint8_t label = 0;  // value in the label image
  uint32_t area_px = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // inclusive box, mask coordinates
  float cx = 0, cy = 0;
};

// Labels (1..n) the 8-connected components of `mask` (non-zero inside) with at least
// `min_area` pixels into `labels` (0 elsewhere); at most kMaxMaskParts, the largest kept.
// `split` applies the neck rule above (neck_ratio in 0..1). Returns the number of parts.
// Errors: masks larger than kMaxSplitPixels (kOutOfRange), label image of another size.
Result<int> MaskParts(ConstGrayView mask, bool split, float neck_ratio, int min_area,
                      MaskPartsScratch& scratch, GrayView labels, MaskPart* parts);

// Morphological opening of `mask` by a disc of radius `ratio` times its largest inscribed
// radius: the pixels within that radius of a pixel at least that far from the border. Parts
// thinner than the disc (the legs of a bracket behind a hexagon) vanish, the part with the
// largest inscribed disc stays with its corners rounded. Writes 255/0 into `out` (the mask's
// size); returns the number of pixels kept. Same errors as MaskParts.
Result<uint32_t> OpenMask(ConstGrayView mask, float ratio, MaskPartsScratch& scratch, GrayView out);

}  // namespace sh
