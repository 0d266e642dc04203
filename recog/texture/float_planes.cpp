#include "recog/texture/float_planes.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace sh::texture {

void ToUnitFloat(const ConstGrayView& image, FloatView out) {
  assert(out.width == image.width && out.height == image.height);
  constexpr float kInv255 = 1.0f / 255.0f;
  for (int y = 0; y < image.height; ++y) {
    const uint8_t* src = image.row(y);
    float* dst = out.row(y);
    for (int x = 0; x < image.width; ++x) dst[x] = src[x] * kInv255;
  }
}

namespace {

// Row pass of BlurPlane for rows [y0, y1).
void BlurRows(const ConstFloatView& in, const GaussianKernel& kernel, FloatView tmp, int y0,
              int y1) {
  const int w = in.width;
  const int r = kernel.radius;
  // Row with replicated borders; bounded by the compile-time maxima.
  float pad[kMaxImageWidth + 2 * kMaxGaussianRadius];
  float* center = pad + r;
  const float t0 = kernel.taps[0];
  for (int y = y0; y < y1; ++y) {
    const float* src = in.row(y);
    for (int i = 0; i < r; ++i) pad[i] = src[0];
    for (int x = 0; x < w; ++x) center[x] = src[x];
    for (int i = 0; i < r; ++i) center[w + i] = src[w - 1];
    float* __restrict dst = tmp.row(y);
    for (int x = 0; x < w; ++x) dst[x] = t0 * center[x];
    for (int j = 1; j <= r; ++j) {
      const float t = kernel.taps[j];
      const float* plus = center + j;
      const float* minus = center - j;
      for (int x = 0; x < w; ++x) dst[x] += t * (plus[x] + minus[x]);
    }
  }
}

}  // namespace

void BlurPlane(const ConstFloatView& in, const GaussianKernel& kernel, FloatView tmp, FloatView out,
               const ParallelFor& parallel) {
  assert(kernel.order == 0);
  assert(tmp.data != in.data && tmp.data != out.data);
  // All rows of the row pass before any column pass reads them.
  ForRowBands(parallel, in.height, [&](int y0, int y1) { BlurRows(in, kernel, tmp, y0, y1); });
  const ConstFloatView rows = tmp;
  ForRowBands(parallel, in.height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) FilterColumnRow(rows, kernel, y, out.row(y));
  });
}

int ResampledSize(int size, float scale) {
  // Largest n with (n - 1) / scale <= size - 1.
  return std::max(1, static_cast<int>(std::floor((size - 1) * scale + 1e-4f)) + 1);
}

void ResampleBilinear(const ConstFloatView& in, float scale, FloatView out,
                      const ParallelFor& parallel) {
  const float inv = 1.0f / scale;
  // Column positions and weights are the same for every row: computed once per call, on the
  // stack (bounded by the largest image).
  int x0s[kMaxImageWidth];
  float wxs[kMaxImageWidth];
  const int w = out.width;
  for (int x = 0; x < w; ++x) {
    const float sx = std::min(x * inv, static_cast<float>(in.width - 1));
    const int x0 = std::min(static_cast<int>(sx), in.width - 2 < 0 ? 0 : in.width - 2);
    x0s[x] = x0;
    wxs[x] = in.width > 1 ? sx - x0 : 0.0f;
  }
  const int x_last = in.width > 1 ? 1 : 0;
  ForRowBands(parallel, out.height, [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      const float sy = std::min(y * inv, static_cast<float>(in.height - 1));
      const int y0 = std::min(static_cast<int>(sy), std::max(0, in.height - 2));
      const float wy = in.height > 1 ? sy - y0 : 0.0f;
      const float* r0 = in.row(y0);
      const float* r1 = in.row(std::min(y0 + 1, in.height - 1));
      float* dst = out.row(y);
      for (int x = 0; x < w; ++x) {
        const int x0 = x0s[x];
        const float wx = wxs[x];
        const float top = r0[x0] + wx * (r0[x0 + x_last] - r0[x0]);
        const float bottom = r1[x0] + wx * (r1[x0 + x_last] - r1[x0]);
        dst[x] = top + wy * (bottom - top);
      }
    }
  });
}

void CentralGradients(const ConstFloatView& in, FloatView gx, FloatView gy,
                      const ParallelFor& parallel) {
  const int w = in.width;
  const int h = in.height;
  ForRowBands(parallel, h, [&](int y_begin, int y_end) {
    for (int y = y_begin; y < y_end; ++y) {
      const float* c = in.row(y);
      const float* up = in.row(y > 0 ? y - 1 : 0);
      const float* down = in.row(y + 1 < h ? y + 1 : h - 1);
      const float ys = (y > 0 && y + 1 < h) ? 0.5f : 1.0f;  // one-sided at the top and bottom
      float* __restrict ox = gx.row(y);
      float* __restrict oy = gy.row(y);
      for (int x = 1; x + 1 < w; ++x) ox[x] = 0.5f * (c[x + 1] - c[x - 1]);
      if (w > 1) {
        ox[0] = c[1] - c[0];
        ox[w - 1] = c[w - 1] - c[w - 2];
      } else {
        ox[0] = 0.0f;
      }
      if (h > 1) {
        for (int x = 0; x < w; ++x) oy[x] = ys * (down[x] - up[x]);
      } else {
        for (int x = 0; x < w; ++x) oy[x] = 0.0f;
      }
    }
  });
}

float SampleBilinear(const ConstFloatView& in, float x, float y) {
  x = std::clamp(x, 0.0f, static_cast<float>(in.width - 1));
  y = std::clamp(y, 0.0f, static_cast<float>(in.height - 1));
  const int x0 = std::min(static_cast<int>(x), std::max(0, in.width - 2));
  const int y0 = std::min(static_cast<int>(y), std::max(0, in.height - 2));
  const int x1 = std::min(x0 + 1, in.width - 1);
  const int y1 = std::min(y0 + 1, in.height - 1);
  const float fx = x - x0;
  const float fy = y - y0;
  const float* r0 = in.row(y0);
  const float* r1 = in.row(y1);
  const float top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const float bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  return top + fy * (bottom - top);
}

}  // namespace sh::texture
