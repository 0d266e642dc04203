#include "recog/shape/shape_window.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace sh {
namespace {

// Integral of a row's values over the continuous interval [a, b] (pixel x covers [x, x + 1]),
// from the row's prefix sums: exact for piecewise-constant pixels.
float RowIntegral(const uint32_t* prefix, const uint8_t* row, int w, float a, float b) {
  auto at = [&](float u) {
    const int k = std::min(w, static_cast<int>(u));
    const float frac = k < w ? u - static_cast<float>(k) : 0.0f;
    return static_cast<float>(prefix[k]) + frac * (k < w ? row[k] : 0);
  };
  return at(b) - at(a);
}

}  // namespace

void NormalisedSize(int w, int h, int k, int* w0, int* h0) {
  if (w >= h) {
    *w0 = k;
    *h0 = static_cast<int>(std::floor(static_cast<double>(k) * h / w + 0.5));
  } else {
    *w0 = static_cast<int>(std::floor(static_cast<double>(k) * w / h + 0.5));
    *h0 = k;
  }
  *w0 = std::max(1, *w0);
  *h0 = std::max(1, *h0);
}

Status ComputeShapeWindow(ConstGrayView mask, ShapeWindowScratch& scratch, ShapeWindow* out) {
  if (mask.empty() || mask.stride < mask.width) {
    return Status::Error(StatusCode::kInvalidArgument, "shape window: empty mask");
  }
  if (mask.width > kMaxImageWidth || mask.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "shape window: mask %dx%d exceeds %dx%d",
                         mask.width, mask.height, kMaxImageWidth, kMaxImageHeight);
  }
  const int w = mask.width, h = mask.height;
  int w0, h0;
  NormalisedSize(w, h, kWindowSide, &w0, &h0);
  // Window pixels per source pixel along each axis (equal up to the rounding of eq. 1).
  const float sx = static_cast<float>(w0) / w, sy = static_cast<float>(h0) / h;

  // Horizontal pass: each source row integrated over the w0 target columns.
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = mask.row(y);
    scratch.prefix[0] = 0;
    for (int x = 0; x < w; ++x) scratch.prefix[x + 1] = scratch.prefix[x] + row[x];
    for (int i = 0; i < w0; ++i) {
      scratch.rows[y][i] = RowIntegral(scratch.prefix, row, w, i / sx, (i + 1) / sx);
    }
  }
  // Vertical pass into the centred w0 x h0 block; the mean over the cell's source area, in
  // units of full coverage (255).
  float coverage[kWindowPixels] = {};
  const int ox = (kWindowSide - w0) / 2, oy = (kWindowSide - h0) / 2;
  const float norm = sx * sy / 255.0f;
  for (int j = 0; j < h0; ++j) {
    const float a = j / sy, b = std::min(static_cast<float>(h), (j + 1) / sy);
    for (int y = static_cast<int>(a); y < h && static_cast<float>(y) < b; ++y) {
      const float weight = std::min(b, y + 1.0f) - std::max(a, static_cast<float>(y));
      if (weight <= 0) continue;
      float* dst = coverage + ptrdiff_t{oy + j} * kWindowSide + ox;
      for (int i = 0; i < w0; ++i) dst[i] += weight * scratch.rows[y][i];
    }
  }
  for (int i = 0; i < kWindowPixels; ++i) coverage[i] *= norm;

  // [1 2 1] / 4 blur in both directions (zero outside the window).
  float tmp[kWindowPixels];
  for (int y = 0; y < kWindowSide; ++y) {
    const float* c = coverage + ptrdiff_t{y} * kWindowSide;
    for (int x = 0; x < kWindowSide; ++x) {
      const float l = x > 0 ? c[x - 1] : 0.0f, r = x + 1 < kWindowSide ? c[x + 1] : 0.0f;
      tmp[y * kWindowSide + x] = 0.25f * (l + 2.0f * c[x] + r);
    }
  }
  for (int y = 0; y < kWindowSide; ++y) {
    for (int x = 0; x < kWindowSide; ++x) {
      const float u = y > 0 ? tmp[(y - 1) * kWindowSide + x] : 0.0f;
      const float d = y + 1 < kWindowSide ? tmp[(y + 1) * kWindowSide + x] : 0.0f;
      coverage[y * kWindowSide + x] = 0.25f * (u + 2.0f * tmp[y * kWindowSide + x] + d);
    }
  }
  // Gradient magnitude by central differences, then unit energy.
  double energy = 0;
  for (int y = 0; y < kWindowSide; ++y) {
    for (int x = 0; x < kWindowSide; ++x) {
      auto c = [&](int xx, int yy) {
        return (xx < 0 || yy < 0 || xx >= kWindowSide || yy >= kWindowSide)
                   ? 0.0f
                   : coverage[yy * kWindowSide + xx];
      };
      const float gx = 0.5f * (c(x + 1, y) - c(x - 1, y));
      const float gy = 0.5f * (c(x, y + 1) - c(x, y - 1));
      const float g = std::sqrt(gx * gx + gy * gy);
      out->v[y * kWindowSide + x] = g;
      energy += double(g) * g;
    }
  }
  if (!(energy > 0)) {
    return Status::Error(StatusCode::kInvalidArgument, "shape window: the mask has no pixel set");
  }
  const float inv = static_cast<float>(1.0 / std::sqrt(energy));
  for (float& v : out->v) v *= inv;
  return Status::Ok();
}

}  // namespace sh
