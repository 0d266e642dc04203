#include "recog/shape/silhouette_placement.hpp"

#include <algorithm>

namespace sh {
namespace {

// Shifts of one axis that keep [lo, lo + size) within [box_lo, box_hi]; when the silhouette is
// the larger, the one shift that centres it on the box.
void ShiftRange(int lo, int size, int box_lo, int box_hi, int* first, int* last) {
  *first = box_lo - lo;
  *last = box_hi - (lo + size - 1);
  if (*first > *last) {
    const int twice = (box_lo + box_hi) - (2 * lo + size - 1);
    *first = *last = twice >= 0 ? twice / 2 : -((1 - twice) / 2);
  }
}

// Silhouette pixels sampled every `step` pixels: as many at every shift.
uint32_t Samples(const SilhouetteMask& s, int step) {
  uint32_t n = 0;
  for (int y = 0; y < s.height; y += step) {
    const uint8_t* m = s.mask + static_cast<size_t>(y) * s.width;
    for (int x = 0; x < s.width; x += step) n += m[x] != 0;
  }
  return n;
}

// Of the `samples` silhouette pixels sampled every `step` pixels, those that land on the blob
// at shift (dx, dy). Given up after a row once the pixels left cannot take the count past
// `beat` (what it has counted then is returned, at most `beat`), unless `must_finish`.
uint32_t Hits(const SilhouetteMask& s, ConstGrayView ids, uint8_t id, ConstGrayView hidden, int dx,
              int dy, int step, uint32_t samples, uint32_t beat, bool must_finish) {
  uint32_t h = 0, n = 0;
  for (int y = 0; y < s.height; y += step) {
    const int iy = s.y0 + y + dy;
    const uint8_t* m = s.mask + static_cast<size_t>(y) * s.width;
    const bool row_inside = iy >= 0 && iy < ids.height;
    const uint8_t* row = row_inside ? ids.row(iy) : nullptr;
    const uint8_t* hid = row_inside && !hidden.empty() ? hidden.row(iy) : nullptr;
    for (int x = 0; x < s.width; x += step) {
      if (m[x] == 0) continue;
      ++n;
      const int ix = s.x0 + x + dx;
      h += row != nullptr && ix >= 0 && ix < ids.width &&
           (row[ix] == id || (hid != nullptr && hid[ix] != 0));
    }
    if (!must_finish && h + (samples - n) <= beat) break;
  }
  return h;
}

struct ShiftBox {
  int x_first = 0, x_last = 0, y_first = 0, y_last = 0;
};

// The shift of `range`, every `shift_step` pixels, whose sampled pixels (every `sample_step`)
// land on the blob most often; the first of equals in row-major order. Returns the hits. A
// shift is given up once it cannot have more hits than the best before it: it would not be
// chosen.
uint32_t BestShift(const SilhouetteMask& s, ConstGrayView ids, uint8_t id, ConstGrayView hidden,
                   const ShiftBox& range, int shift_step, int sample_step, int* best_dx,
                   int* best_dy, uint32_t* samples) {
  *samples = Samples(s, sample_step);
  uint32_t best_hits = 0;
  bool any = false;
  for (int dy = range.y_first; dy <= range.y_last; dy += shift_step) {
    for (int dx = range.x_first; dx <= range.x_last; dx += shift_step) {
      const uint32_t hits =
          Hits(s, ids, id, hidden, dx, dy, sample_step, *samples, best_hits, !any);
      if (!any || hits > best_hits) {
        best_hits = hits;
        *best_dx = dx;
        *best_dy = dy;
        any = true;
      }
    }
  }
  return best_hits;
}

}  // namespace

bool PlaceSilhouette(const SilhouetteMask& silhouette, ConstGrayView ids, uint8_t id,
                     ConstGrayView hidden, const PixelBox& box, Placement* out) {
  if (silhouette.empty() || silhouette.mask == nullptr) return false;
  constexpr int kCoarseStep = 4;  // shifts and samples of the first search, pixels
  constexpr int kFineStep = 2;    // samples of the second
  constexpr int kFineRadius = kCoarseStep - 1;
  ShiftBox all;
  ShiftRange(silhouette.x0, silhouette.width, box.x0, box.x1, &all.x_first, &all.x_last);
  ShiftRange(silhouette.y0, silhouette.height, box.y0, box.y1, &all.y_first, &all.y_last);
  int dx = 0, dy = 0;
  uint32_t samples = 0;
  BestShift(silhouette, ids, id, hidden, all, kCoarseStep, kCoarseStep, &dx, &dy, &samples);
  // Every shift around the best, within the range.
  const ShiftBox near{
      std::max(all.x_first, dx - kFineRadius), std::min(all.x_last, dx + kFineRadius),
      std::max(all.y_first, dy - kFineRadius), std::min(all.y_last, dy + kFineRadius)};
  const uint32_t hits =
      BestShift(silhouette, ids, id, hidden, near, 1, kFineStep, &dx, &dy, &samples);
  out->dx = dx;
  out->dy = dy;
  out->overlap = samples ? static_cast<float>(hits) / static_cast<float>(samples) : 0.0f;
  return true;
}

}  // namespace sh
