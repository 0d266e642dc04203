// Where a predicted silhouette fits best inside a blob that is larger than it: the blob is then
// a merger (a part in front of another of its colour, one region), and its centroid lies
// between the parts, so the centroid is no place to start the part from. The silhouette is slid
// over the blob's pixels, its box kept within the blob's box, to the shift that puts most of
// its pixels on the blob: a coarse grid of shifts on a sparse sampling of the silhouette, then
// every shift around the best on a denser one. Of equal overlaps the first shift found wins
// (row-major from the top left), so the result does not depend on anything but the inputs.
#pragma once

#include <cstdint>

#include "recog/image/image.hpp"
#include "recog/shape/silhouette.hpp"

namespace sh {

struct PixelBox {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive
};

struct Placement {
  int dx = 0, dy = 0;  // shift of the silhouette, pixels
  float overlap = 0;   // share of the silhouette's sampled pixels on the blob at that shift
};

// `ids`: the image's blob ids (one byte a pixel), `id` the blob's, `box` its bounding box;
// `hidden` (same size, or empty): pixels where the part may be hidden by a part in front of it,
// which count as fitting too.
// Returns false for an empty silhouette.
bool PlaceSilhouette(const SilhouetteMask& silhouette, ConstGrayView ids, uint8_t id,
                     ConstGrayView hidden, const PixelBox& box, Placement* out);

}  // namespace sh
