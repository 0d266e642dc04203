#include "recog/image/corners.hpp"

#include <algorithm>
#include <cmath>

namespace sh {

namespace {

// Refinement window: radius around the detected maximum, and the gradient kernel margin.
constexpr int kMaxRefineRadiusPx = static_cast<int>(2.5f * kMaxGaussianSigmaPx) + 3;
constexpr int kMaxRefineMarginPx = 4;  // gradient kernel radius for refine_sigma_px <= 1.33
constexpr float kMaxRefineSigmaPx = kMaxRefineMarginPx / 3.0f;
constexpr int kRefineSide = 2 * (kMaxRefineRadiusPx + kMaxRefineMarginPx) + 1;

// Min-heap order on strength so that the weakest kept corner is at the front; equal strengths
// keep the earlier (raster order) corner.
bool StrongerFirst(const Corner2D& a, const Corner2D& b) { return a.strength > b.strength; }

// Keeps the strongest corners: plain push while there is room, then a min-heap replace.
void KeepStrongest(Vector<Corner2D>& out, const Corner2D& c, bool& heap_built, size_t& dropped) {
  if (out.push_back(c)) return;
  if (!heap_built) {
    std::make_heap(out.begin(), out.end(), StrongerFirst);
    heap_built = true;
  }
  if (c.strength <= out[0].strength) {
    ++dropped;
    return;
  }
  std::pop_heap(out.begin(), out.end(), StrongerFirst);
  out.back() = c;
  std::push_heap(out.begin(), out.end(), StrongerFirst);
  ++dropped;
}

// Fused column pass: the five derivatives of one output row from the three row-filtered planes,
// then the normalised response. Symmetric taps fold the +k/-k rows (sums), antisymmetric taps use
// their differences, so each row pair is read once for all five derivatives.
void ResponseRow(const float* const* r0, const float* const* r1, const float* const* r2, int r,
                 const GaussianKernel& g0, const GaussianKernel& g1, const GaussianKernel& g2,
                 int width, float scale, float* out, float* ix, float* iy, float* ixx, float* ixy,
                 float* iyy) {
  {
    const float* a = r0[r];
    const float* b = r1[r];
    const float* c = r2[r];
    for (int x = 0; x < width; ++x) {
      ix[x] = g0.taps[0] * b[x];
      iy[x] = 0.0f;
      ixx[x] = g0.taps[0] * c[x];
      ixy[x] = 0.0f;
      iyy[x] = g2.taps[0] * a[x];
    }
  }
  for (int k = 1; k <= r; ++k) {
    const float* ap = r0[r + k];
    const float* am = r0[r - k];
    const float* bp = r1[r + k];
    const float* bm = r1[r - k];
    const float* cp = r2[r + k];
    const float* cm = r2[r - k];
    const float t0 = g0.taps[k];
    const float t1 = g1.taps[k];
    const float t2 = g2.taps[k];
    for (int x = 0; x < width; ++x) {
      ix[x] += t0 * (bp[x] + bm[x]);
      iy[x] += t1 * (ap[x] - am[x]);
      ixx[x] += t0 * (cp[x] + cm[x]);
      ixy[x] += t1 * (bp[x] - bm[x]);
      iyy[x] += t2 * (ap[x] + am[x]);
    }
  }
  for (int x = 0; x < width; ++x) {
    const float n = iy[x] * iy[x] * ixx[x] - 2.0f * ix[x] * iy[x] * ixy[x] + ix[x] * ix[x] * iyy[x];
    out[x] = std::fabs(n) * scale;
  }
}

// Response row from the smoothed image by central differences (rows y - 1, y, y + 1; borders
// replicated).
void DifferenceResponseRow(const float* __restrict up, const float* __restrict mid,
                           const float* __restrict down, int width, float scale,
                           float* __restrict out) {
  auto response = [&](int xm, int x, int xp) {
    const float ix = 0.5f * (mid[xp] - mid[xm]);
    const float iy = 0.5f * (down[x] - up[x]);
    const float ixx = mid[xp] - 2.0f * mid[x] + mid[xm];
    const float iyy = down[x] - 2.0f * mid[x] + up[x];
    const float ixy = 0.25f * (down[xp] - down[xm] - up[xp] + up[xm]);
    return std::fabs(iy * iy * ixx - 2.0f * ix * iy * ixy + ix * ix * iyy) * scale;
  };
  for (int x = 1; x < width - 1; ++x) out[x] = response(x - 1, x, x + 1);
  out[0] = response(0, 0, std::min(1, width - 1));
  if (width > 1) out[width - 1] = response(width - 2, width - 1, width - 1);
}

// Largest value of a row. Eight independent running maxima let the compiler vectorise the loop
// (a single running std::max is a serial dependency chain); max is exact, so the result does not
// depend on the order.
float RowMax(const float* __restrict row, int width, float init) {
  constexpr int kLanes = 8;
  float lane[kLanes];
  for (int i = 0; i < kLanes; ++i) lane[i] = init;
  int x = 0;
  for (; x + kLanes <= width; x += kLanes) {
    for (int i = 0; i < kLanes; ++i) lane[i] = lane[i] > row[x + i] ? lane[i] : row[x + i];
  }
  float m = init;
  for (int i = 0; i < kLanes; ++i) m = std::max(m, lane[i]);
  for (; x < width; ++x) m = std::max(m, row[x]);
  return m;
}

bool IsLocalMax(const ImageView<const float>& resp, int x, int y, int radius) {
  const float v = resp.row(y)[x];
  const int y0 = std::max(0, y - radius), y1 = std::min(resp.height - 1, y + radius);
  const int x0 = std::max(0, x - radius), x1 = std::min(resp.width - 1, x + radius);
  for (int yy = y0; yy <= y1; ++yy) {
    const float* row = resp.row(yy);
    for (int xx = x0; xx <= x1; ++xx) {
      const float q = row[xx];
      // Raster-order tie break: an equal value earlier in the scan wins.
      const bool before = yy < y || (yy == y && xx < x);
      if (q > v || (before && q == v)) return false;
    }
  }
  return true;
}

// Sub-pixel offset of the maximum from a quadratic fit to the 3x3 neighbourhood.
void QuadraticPeak(const ImageView<const float>& resp, int x, int y, float& dx_out, float& dy_out) {
  dx_out = dy_out = 0.0f;
  if (x < 1 || y < 1 || x >= resp.width - 1 || y >= resp.height - 1) return;
  auto at = [&](int dx, int dy) { return resp.row(y + dy)[x + dx]; };
  const float c = at(0, 0);
  const float gx = 0.5f * (at(1, 0) - at(-1, 0));
  const float gy = 0.5f * (at(0, 1) - at(0, -1));
  const float hxx = at(1, 0) - 2.0f * c + at(-1, 0);
  const float hyy = at(0, 1) - 2.0f * c + at(0, -1);
  const float hxy = 0.25f * (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1));
  const float det = hxx * hyy - hxy * hxy;
  if (hxx < 0.0f && det > 0.0f) {
    const float dx = -(hyy * gx - hxy * gy) / det;
    const float dy = -(hxx * gy - hxy * gx) / det;
    if (std::fabs(dx) <= 1.0f && std::fabs(dy) <= 1.0f) {
      dx_out = dx;
      dy_out = dy;
      return;
    }
  }
  // Fall back to independent 1-D parabolas, which cannot leave the pixel.
  if (hxx < 0.0f) dx_out = std::clamp(-gx / hxx, -0.5f, 0.5f);
  if (hyy < 0.0f) dy_out = std::clamp(-gy / hyy, -0.5f, 0.5f);
}

// Moves a corner to the least-squares intersection of the edge lines around it: minimises
// sum_q w(q) (g(q) . (c - q))^2 over the window, with gradients g at refine_sigma_px and a
// Gaussian weight around the current estimate. Returns false (leaving c) when the gradients do
// not span two directions or the result leaves the window.
bool RefineToVertex(const ConstGrayView& image, const CornerConfig& config, Corner2D& c) {
  const int window =
      std::min(kMaxRefineRadiusPx, static_cast<int>(std::ceil(2.5f * config.sigma_px)) + 2);
  GaussianKernel g0, g1;
  if (!MakeGaussianKernel(config.refine_sigma_px, 0, g0).ok() ||
      !MakeGaussianKernel(config.refine_sigma_px, 1, g1).ok()) {
    return false;
  }
  const int m = g0.radius;  // <= kMaxRefineMarginPx, checked by ValidateCornerConfig
  const int cx = static_cast<int>(std::lround(c.x_px));
  const int cy = static_cast<int>(std::lround(c.y_px));
  const int side = 2 * window + 1;
  const int pside = side + 2 * m;
  // Patch with margin m, borders replicated; then x and y derivatives of the window.
  float patch[kRefineSide * kRefineSide];
  for (int j = 0; j < pside; ++j) {
    const int yy = std::clamp(cy - window - m + j, 0, image.height - 1);
    const uint8_t* row = image.row(yy);
    for (int i = 0; i < pside; ++i) {
      patch[j * pside + i] = row[std::clamp(cx - window - m + i, 0, image.width - 1)];
    }
  }
  auto p = [&](int i, int j) { return patch[(j + m) * pside + (i + m)]; };
  float gx[(2 * kMaxRefineRadiusPx + 1) * (2 * kMaxRefineRadiusPx + 1)];
  float gy[(2 * kMaxRefineRadiusPx + 1) * (2 * kMaxRefineRadiusPx + 1)];
  // Direct 2-D separable sums: the window is small and this runs for reported corners only.
  float rx[kRefineSide * kRefineSide];  // row-filtered with g1 (x derivative), rows -m..side+m
  float ry[kRefineSide * kRefineSide];  // row-filtered with g0
  for (int j = -m; j < side + m; ++j) {
    for (int i = 0; i < side; ++i) {
      float sx = 0.0f, sy = g0.taps[0] * p(i, j);
      for (int k = 1; k <= m; ++k) {
        sx += g1.taps[k] * (p(i + k, j) - p(i - k, j));
        sy += g0.taps[k] * (p(i + k, j) + p(i - k, j));
      }
      rx[(j + m) * side + i] = sx;
      ry[(j + m) * side + i] = sy;
    }
  }
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      float sx = g0.taps[0] * rx[(j + m) * side + i], sy = 0.0f;
      for (int k = 1; k <= m; ++k) {
        sx += g0.taps[k] * (rx[(j + m + k) * side + i] + rx[(j + m - k) * side + i]);
        sy += g1.taps[k] * (ry[(j + m + k) * side + i] - ry[(j + m - k) * side + i]);
      }
      gx[j * side + i] = sx;
      gy[j * side + i] = sy;
    }
  }
  const float weight_sigma = std::max(1.5f, 1.2f * config.sigma_px);
  const float inv_2s2 = 0.5f / (weight_sigma * weight_sigma);
  float ex = c.x_px, ey = c.y_px;
  for (int iter = 0; iter < 4; ++iter) {
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) {
        const float qx = static_cast<float>(cx - window + i);
        const float qy = static_cast<float>(cy - window + j);
        const float d2 = (qx - ex) * (qx - ex) + (qy - ey) * (qy - ey);
        if (d2 > static_cast<float>(window * window)) continue;
        const float w = std::exp(-d2 * inv_2s2);
        const double x = gx[j * side + i], y = gy[j * side + i];
        const double wxx = w * x * x, wxy = w * x * y, wyy = w * y * y;
        a11 += wxx;
        a12 += wxy;
        a22 += wyy;
        b1 += wxx * qx + wxy * qy;
        b2 += wxy * qx + wyy * qy;
      }
    }
    const double tr = a11 + a22;
    const double det = a11 * a22 - a12 * a12;
    // Smaller eigenvalue relative to the trace: near zero on a straight edge.
    const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
    const double lmin = 0.5 * tr - disc;
    if (!(tr > 0.0) || lmin < 0.05 * tr) return false;
    const float nx = static_cast<float>((a22 * b1 - a12 * b2) / det);
    const float ny = static_cast<float>((a11 * b2 - a12 * b1) / det);
    const float move = std::hypot(nx - ex, ny - ey);
    ex = nx;
    ey = ny;
    if (std::hypot(ex - c.x_px, ey - c.y_px) > static_cast<float>(window)) return false;
    if (move < 0.01f) break;
  }
  c.x_px = std::clamp(ex, 0.0f, static_cast<float>(image.width - 1));
  c.y_px = std::clamp(ey, 0.0f, static_cast<float>(image.height - 1));
  return true;
}

}  // namespace

Status ValidateCornerConfig(const CornerConfig& config) {
  if (!(config.sigma_px >= kMinGaussianSigmaPx && config.sigma_px <= kMaxGaussianSigmaPx)) {
    return Status::Error(StatusCode::kOutOfRange, "corner sigma_c %.3f px outside [%.2f, %.2f]",
                         static_cast<double>(config.sigma_px),
                         static_cast<double>(kMinGaussianSigmaPx),
                         static_cast<double>(kMaxGaussianSigmaPx));
  }
  if (!(config.threshold >= 0.0f) || !(config.relative_threshold >= 0.0f) ||
      !(config.relative_threshold <= 1.0f)) {
    return Status::Error(
        StatusCode::kInvalidArgument, "corner thresholds must be >= 0 (relative <= 1): %g, %g",
        static_cast<double>(config.threshold), static_cast<double>(config.relative_threshold));
  }
  if (config.nms_radius_px < 1 || config.nms_radius_px > kMaxCornerNmsRadiusPx) {
    return Status::Error(StatusCode::kOutOfRange, "corner NMS radius %d px outside [1, %d]",
                         config.nms_radius_px, kMaxCornerNmsRadiusPx);
  }
  if (config.refine_to_vertex && !(config.refine_sigma_px >= kMinGaussianSigmaPx &&
                                   config.refine_sigma_px <= kMaxRefineSigmaPx)) {
    return Status::Error(
        StatusCode::kOutOfRange, "corner refine sigma %.3f px outside [%.2f, %.2f]",
        static_cast<double>(config.refine_sigma_px), static_cast<double>(kMinGaussianSigmaPx),
        static_cast<double>(kMaxRefineSigmaPx));
  }
  return Status::Ok();
}

Status DetectCorners(const ConstGrayView& image, const CornerConfig& config, FilterScratch& scratch,
                     Vector<Corner2D>& corners, CornerStats* stats) {
  corners.clear();
  if (stats != nullptr) *stats = CornerStats{};
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "DetectCorners"));
  SH_RETURN_IF_ERROR(ValidateCornerConfig(config));
  const int w = image.width, h = image.height;
  ImageView<float> resp = scratch.planes[3].view(w, h);
  // Normalisation: derivatives of total order 4 scale as sigma^-4 and N as contrast^3.
  const double s2 = double{config.sigma_px} * config.sigma_px;
  const float scale = static_cast<float>(s2 * s2 / (255.0 * 255.0 * 255.0 * kIdealCornerResponse));
  float max_strength = 0.0f;
  const float smooth_sigma = std::sqrt(std::max(0.0f, config.sigma_px * config.sigma_px - 0.25f));
  if (!config.exact_derivatives && smooth_sigma >= kMinGaussianSigmaPx) {
    GaussianKernel g0;
    SH_RETURN_IF_ERROR(MakeGaussianKernel(smooth_sigma, 0, g0));
    ImageView<float> rows = scratch.planes[0].view(w, h);
    ImageView<float> smooth = scratch.planes[1].view(w, h);
    FilterRows(image, &g0, rows, nullptr, {}, nullptr, {});
    // Column pass row by row, each response row as soon as its lower neighbour exists: the three
    // smoothed rows are still in cache.
    auto response_row = [&](int y) {
      float* out = resp.row(y);
      DifferenceResponseRow(smooth.row(std::max(0, y - 1)), smooth.row(y),
                            smooth.row(std::min(h - 1, y + 1)), w, scale, out);
      max_strength = RowMax(out, w, max_strength);
    };
    for (int y = 0; y < h; ++y) {
      FilterColumnRow(rows, g0, y, smooth.row(y));
      if (y >= 1) response_row(y - 1);
    }
    response_row(h - 1);
  } else {
    GaussianKernel g0, g1, g2;
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 0, g0));
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 1, g1));
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 2, g2));
    const int r = g0.radius;
    ImageView<float> p0 = scratch.planes[0].view(w, h);
    ImageView<float> p1 = scratch.planes[1].view(w, h);
    ImageView<float> p2 = scratch.planes[2].view(w, h);
    FilterRows(image, &g0, p0, &g1, p1, &g2, p2);
    const float* rows0[2 * kMaxGaussianRadius + 1];
    const float* rows1[2 * kMaxGaussianRadius + 1];
    const float* rows2[2 * kMaxGaussianRadius + 1];
    float ix[kMaxImageWidth], iy[kMaxImageWidth], ixx[kMaxImageWidth], ixy[kMaxImageWidth],
        iyy[kMaxImageWidth];
    for (int y = 0; y < h; ++y) {
      ClampedRowPointers(p0, y, r, rows0);
      ClampedRowPointers(p1, y, r, rows1);
      ClampedRowPointers(p2, y, r, rows2);
      float* out = resp.row(y);
      ResponseRow(rows0, rows1, rows2, r, g0, g1, g2, w, scale, out, ix, iy, ixx, ixy, iyy);
      max_strength = RowMax(out, w, max_strength);
    }
  }
  const float threshold = std::max(config.threshold, config.relative_threshold * max_strength);

  bool heap_built = false;
  size_t found = 0, dropped = 0;
  const ImageView<const float> cresp = resp;
  for (int y = 0; y < h; ++y) {
    const float* row = cresp.row(y);
    for (int x = 0; x < w; ++x) {
      // Strictly above: a zero threshold must not turn flat regions into corners.
      if (!(row[x] > threshold)) continue;
      if (!IsLocalMax(cresp, x, y, config.nms_radius_px)) continue;
      float dx, dy;
      QuadraticPeak(cresp, x, y, dx, dy);
      ++found;
      KeepStrongest(corners, Corner2D{x + dx, y + dy, row[x]}, heap_built, dropped);
    }
  }
  // std::sort (not stable_sort, which may allocate) with a total order: strength, then raster.
  std::sort(corners.begin(), corners.end(), [](const Corner2D& a, const Corner2D& b) {
    if (a.strength != b.strength) return a.strength > b.strength;
    if (a.y_px != b.y_px) return a.y_px < b.y_px;
    return a.x_px < b.x_px;
  });
  size_t refined = 0;
  if (config.refine_to_vertex) {
    for (Corner2D& c : corners) refined += RefineToVertex(image, config, c) ? 1 : 0;
  }
  if (stats != nullptr) {
    stats->max_strength = max_strength;
    stats->threshold_used = threshold;
    stats->maxima_found = found;
    stats->maxima_dropped = dropped;
    stats->vertex_refined = refined;
  }
  return Status::Ok();
}

}  // namespace sh
