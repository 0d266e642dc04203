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

// Whether any of kScanBlock values exceeds t: four running maxima (max is exact, so the order does
// not matter), which the compiler maps onto one vector register; a count of the comparisons or a
// single running maximum stays scalar.
constexpr int kScanBlock = 16;
bool AnyAbove(const float* __restrict v, float t) {
  float lane[4] = {v[0], v[1], v[2], v[3]};
  for (int k = 4; k < kScanBlock; k += 4) {
    for (int i = 0; i < 4; ++i) lane[i] = lane[i] > v[k + i] ? lane[i] : v[k + i];
  }
  const float m = std::max(std::max(lane[0], lane[1]), std::max(lane[2], lane[3]));
  return m > t;
}

// The response rows of an image of width x height in FilterScratch::response: row y in slot
// y % kResponseRows, valid for the last kResponseRows rows written.
struct ResponseRing {
  float* data = nullptr;
  int width = 0, height = 0;
  float* row(int y) const {
    return data +
           static_cast<size_t>(y % FilterScratch::kResponseRows) * static_cast<size_t>(width);
  }
};
static_assert(FilterScratch::kResponseRows >= 2 * kMaxCornerNmsRadiusPx + 1,
              "the ring holds a row's whole neighbourhood");

bool IsLocalMax(const ResponseRing& resp, int x, int y, int radius) {
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
void QuadraticPeak(const ResponseRing& resp, int x, int y, float& dx_out, float& dy_out) {
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
    // The Gaussian weight is separable: one exponential per column and per row of the window
    // instead of one per pixel.
    float wcol[2 * kMaxRefineRadiusPx + 1], wrow[2 * kMaxRefineRadiusPx + 1];
    for (int i = 0; i < side; ++i) {
      const float dx = static_cast<float>(cx - window + i) - ex;
      const float dy = static_cast<float>(cy - window + i) - ey;
      wcol[i] = std::exp(-dx * dx * inv_2s2);
      wrow[i] = std::exp(-dy * dy * inv_2s2);
    }
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) {
        const float qx = static_cast<float>(cx - window + i);
        const float qy = static_cast<float>(cy - window + j);
        const float d2 = (qx - ex) * (qx - ex) + (qy - ey) * (qy - ey);
        if (d2 > static_cast<float>(window * window)) continue;
        const float w = wcol[i] * wrow[j];
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
    if (iter == 0) c.isotropy = tr > 0.0 ? static_cast<float>(lmin / tr) : 0.0f;
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

namespace {

// Whether the full image is smoothed at DifferenceSmoothingSigma(sigma_c) and differentiated by
// central differences: neither exact_derivatives nor the reduced path, and sigma_c large enough
// for the smoothing.
bool CornersUseSmoothedImage(const CornerConfig& config) {
  return !config.exact_derivatives &&
         !(config.reduce_large_scales && config.sigma_px >= kCornerReduceSigmaPx) &&
         config.sigma_px * config.sigma_px - 0.25f >= kMinGaussianSigmaPx * kMinGaussianSigmaPx;
}

// Factor that normalises the response (see Corner2D::strength).
float CornerResponseScale(float sigma_px) {
  // Derivatives of total order 4 scale as sigma^-4 and N as contrast^3.
  const double s2 = double{sigma_px} * sigma_px;
  return static_cast<float>(s2 * s2 / (255.0 * 255.0 * 255.0 * kIdealCornerResponse));
}

// Normalised response of row `mid` of the smoothed image from central differences, `up` and
// `down` being its neighbours (the row itself at the image border); returns the row's maximum.
float CornerResponseRow(const float* __restrict up, const float* __restrict mid,
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
  // The interior spelled out with fixed offsets (same arithmetic as `response`) vectorises; the
  // index form does not.
  for (int x = 1; x < width - 1; ++x) {
    const float ix = 0.5f * (mid[x + 1] - mid[x - 1]);
    const float iy = 0.5f * (down[x] - up[x]);
    const float ixx = mid[x + 1] - 2.0f * mid[x] + mid[x - 1];
    const float iyy = down[x] - 2.0f * mid[x] + up[x];
    const float ixy = 0.25f * (down[x + 1] - down[x - 1] - up[x + 1] + up[x - 1]);
    out[x] = std::fabs(iy * iy * ixx - 2.0f * ix * iy * ixy + ix * ix * iyy) * scale;
  }
  out[0] = response(0, 0, std::min(1, width - 1));
  if (width > 1) out[width - 1] = response(width - 2, width - 1, width - 1);
  return RowMax(out, width, 0.0f);
}

// Corners of a response computed on the image reduced by `factor` (1 or 2), a row at a time in
// raster order once the rows within the NMS radius exist: positions are scaled back to the full
// image, whose pixels the vertex refinement uses.
class CornerCollector {
 public:
  CornerCollector(const ConstGrayView& image, const CornerConfig& config, float max_strength,
                  int nms_radius, int factor, Vector<Corner2D>& corners)
      : image_(image),
        config_(config),
        max_strength_(max_strength),
        threshold_(std::max(config.threshold, config.relative_threshold * max_strength)),
        nms_radius_(nms_radius),
        factor_(factor),
        corners_(corners) {
    corners_.clear();
  }

  // Row y of `resp`; rows y - nms_radius .. y + nms_radius (within the image) are in the ring.
  void Row(const ResponseRing& resp, int y) {
    const float* row = resp.row(y);
    for (int x0 = 0; x0 < resp.width; x0 += kScanBlock) {
      const int x1 = std::min(resp.width, x0 + kScanBlock);
      // Most of the plane is below the threshold: skip whole blocks at once.
      if (x1 - x0 == kScanBlock && !AnyAbove(row + x0, threshold_)) continue;
      for (int x = x0; x < x1; ++x) {
        // Strictly above: a zero threshold must not turn flat regions into corners.
        if (!(row[x] > threshold_)) continue;
        if (!IsLocalMax(resp, x, y, nms_radius_)) continue;
        float dx, dy;
        QuadraticPeak(resp, x, y, dx, dy);
        ++found_;
        const float fx = std::min(static_cast<float>(factor_) * (x + dx), image_.width - 1.0f);
        const float fy = std::min(static_cast<float>(factor_) * (y + dy), image_.height - 1.0f);
        KeepStrongest(corners_, Corner2D{fx, fy, row[x]}, heap_built_, dropped_);
      }
    }
  }

  void Finish(CornerStats* stats) {
    // std::sort (not stable_sort, which may allocate) with a total order: strength, then raster.
    std::sort(corners_.begin(), corners_.end(), [](const Corner2D& a, const Corner2D& b) {
      if (a.strength != b.strength) return a.strength > b.strength;
      if (a.y_px != b.y_px) return a.y_px < b.y_px;
      return a.x_px < b.x_px;
    });
    size_t refined = 0;
    if (config_.refine_to_vertex) {
      for (Corner2D& c : corners_) refined += RefineToVertex(image_, config_, c) ? 1 : 0;
    }
    if (stats != nullptr) {
      stats->max_strength = max_strength_;
      stats->threshold_used = threshold_;
      stats->maxima_found = found_;
      stats->maxima_dropped = dropped_;
      stats->vertex_refined = refined;
    }
  }

 private:
  const ConstGrayView& image_;
  const CornerConfig& config_;
  float max_strength_, threshold_;
  int nms_radius_, factor_;
  Vector<Corner2D>& corners_;
  bool heap_built_ = false;
  size_t found_ = 0, dropped_ = 0;
};

// Smooths `image` at smooth_sigma and writes the difference response row by row into `resp`,
// calling on_row(y) after row y; returns the maximum. Runs in row bands (RowBand): the row pass
// fills ring 0 as the column pass needs it, the column pass writes the smoothed rows to ring 1,
// and each response row follows as soon as its lower neighbour exists.
template <typename OnRow>
float SmoothedResponse(const ConstGrayView& image, const GaussianKernel& g0, float scale,
                       FilterScratch& scratch, const ResponseRing& resp, OnRow&& on_row) {
  const int w = image.width, h = image.height;
  const int r = g0.radius;
  RowBand band(image, scratch, &g0);
  const float* rows[2 * kMaxGaussianRadius + 1];
  float max_strength = 0.0f;
  auto response_row = [&](int y) {
    max_strength =
        std::max(max_strength,
                 CornerResponseRow(band.RingRow(1, std::max(0, y - 1)), band.RingRow(1, y),
                                   band.RingRow(1, std::min(h - 1, y + 1)), w, scale, resp.row(y)));
    on_row(y);
  };
  for (int y = 0; y < h; ++y) {
    band.FillTo(y + r);
    band.RowPointers(0, y, r, rows);
    FilterColumnRowFrom(rows, g0, w, band.RingRow(1, y));
    if (y >= 1) response_row(y - 1);
  }
  response_row(h - 1);
  return max_strength;
}

// The five Gaussian-derivative convolutions at sigma_c (exact_derivatives), in row bands: the
// three row-filtered planes are rings 0-2 of a RowBand. Rows go to `resp` as SmoothedResponse's.
template <typename OnRow>
float ExactResponse(const ConstGrayView& image, const GaussianKernel& g0, const GaussianKernel& g1,
                    const GaussianKernel& g2, float scale, FilterScratch& scratch,
                    const ResponseRing& resp, OnRow&& on_row) {
  const int w = image.width, h = image.height;
  const int r = g0.radius;
  RowBand band(image, scratch, &g0, &g1, &g2);
  const float* rows0[2 * kMaxGaussianRadius + 1];
  const float* rows1[2 * kMaxGaussianRadius + 1];
  const float* rows2[2 * kMaxGaussianRadius + 1];
  float ix[kMaxImageWidth], iy[kMaxImageWidth], ixx[kMaxImageWidth], ixy[kMaxImageWidth],
      iyy[kMaxImageWidth];
  float max_strength = 0.0f;
  for (int y = 0; y < h; ++y) {
    band.FillTo(y + r);
    band.RowPointers(0, y, r, rows0);
    band.RowPointers(1, y, r, rows1);
    band.RowPointers(2, y, r, rows2);
    float* out = resp.row(y);
    ResponseRow(rows0, rows1, rows2, r, g0, g1, g2, w, scale, out, ix, iy, ixx, ixy, iyy);
    max_strength = RowMax(out, w, max_strength);
    on_row(y);
  }
  return max_strength;
}

// The response of the full-size image (not the reduced path) for `config`, rows to `resp` and
// on_row(y) after each; returns the maximum.
template <typename OnRow>
Status FullSizeResponse(const ConstGrayView& image, const CornerConfig& config,
                        FilterScratch& scratch, const ResponseRing& resp, float& max_strength,
                        OnRow&& on_row) {
  const float scale = CornerResponseScale(config.sigma_px);
  if (CornersUseSmoothedImage(config)) {
    GaussianKernel g0;
    SH_RETURN_IF_ERROR(MakeGaussianKernel(DifferenceSmoothingSigma(config.sigma_px), 0, g0));
    max_strength = SmoothedResponse(image, g0, scale, scratch, resp, on_row);
  } else {
    GaussianKernel g0, g1, g2;
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 0, g0));
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 1, g1));
    SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 2, g2));
    max_strength = ExactResponse(image, g0, g1, g2, scale, scratch, resp, on_row);
  }
  return Status::Ok();
}

// Two passes over the response rows: the first for the maximum (the relative threshold needs
// it before any corner is taken), the second computes the same rows again (the same floats) and
// takes the corners of row y once row y + nms_radius exists. `produce(on_row)` writes the rows
// to `resp` in order and returns the maximum.
template <typename Produce>
Status CornersInTwoPasses(const ConstGrayView& image, const CornerConfig& config,
                          const ResponseRing& resp, int nms_radius, int factor,
                          Vector<Corner2D>& corners, CornerStats* stats, Produce&& produce) {
  float max_strength = 0.0f;
  SH_RETURN_IF_ERROR(produce([](int) {}, max_strength));
  CornerCollector collector(image, config, max_strength, nms_radius, factor, corners);
  float again = 0.0f;
  SH_RETURN_IF_ERROR(produce(
      [&](int y) {
        if (y >= nms_radius) collector.Row(resp, y - nms_radius);
      },
      again));
  for (int y = std::max(0, resp.height - nms_radius); y < resp.height; ++y) {
    collector.Row(resp, y);
  }
  collector.Finish(stats);
  return Status::Ok();
}

// 2x reduction: the binomial (1 4 6 4 1) / 16 (variance 1 px^2, zero response at the Nyquist
// frequency) along both axes, kept at even columns and rows, borders replicated. The sums are
// exact integers (at most 255 * 256); the result is rounded to grey levels, an error far below
// the sensor noise once the reduced image is smoothed at sigma_c / 2.
ConstGrayView ReduceImage(const ConstGrayView& image, uint8_t* out) {
  const int w = image.width, h = image.height;
  const int rw = (w + 1) / 2, rh = (h + 1) / 2;
  // Horizontal sums of the source rows, in a ring: output row j needs source rows 2j-2..2j+2.
  constexpr int kRing = 8;
  uint16_t hsum[kRing][(kMaxImageWidth + 1) / 2];
  int ring_row[kRing];
  for (int& r : ring_row) r = -1;
  uint16_t pad[kMaxImageWidth + 4];
  auto horizontal = [&](int y) -> const uint16_t* {
    uint16_t* dst = hsum[y % kRing];
    if (ring_row[y % kRing] == y) return dst;
    ring_row[y % kRing] = y;
    const uint8_t* src = image.row(y);
    pad[0] = pad[1] = src[0];
    for (int x = 0; x < w; ++x) pad[x + 2] = src[x];
    pad[w + 2] = pad[w + 3] = src[w - 1];
    for (int i = 0; i < rw; ++i) {
      const uint16_t* p = pad + ptrdiff_t{2} * i;  // p[2] is source column 2i
      dst[i] = static_cast<uint16_t>(p[0] + 4 * p[1] + 6 * p[2] + 4 * p[3] + p[4]);
    }
    return dst;
  };
  for (int j = 0; j < rh; ++j) {
    const uint16_t* r[5];
    for (int k = 0; k < 5; ++k) r[k] = horizontal(std::clamp(2 * j - 2 + k, 0, h - 1));
    uint8_t* dst = out + static_cast<size_t>(j) * rw;
    for (int i = 0; i < rw; ++i) {
      const uint32_t v = r[0][i] + 4u * r[1][i] + 6u * r[2][i] + 4u * r[3][i] + r[4][i];
      dst[i] = static_cast<uint8_t>((v + 128u) >> 8);
    }
  }
  return {out, rw, rh, rw};
}

}  // namespace

Status DetectCorners(const ConstGrayView& image, const CornerConfig& config, FilterScratch& scratch,
                     Vector<Corner2D>& corners, CornerStats* stats) {
  corners.clear();
  if (stats != nullptr) *stats = CornerStats{};
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "DetectCorners"));
  SH_RETURN_IF_ERROR(ValidateCornerConfig(config));
  SH_RETURN_IF_ERROR(CheckFitsWorkspace(image.width, image.height, scratch.block(),
                                        "DetectCorners (filter scratch)"));
  const int w = image.width, h = image.height;
  if (!config.exact_derivatives && config.reduce_large_scales &&
      config.sigma_px >= kCornerReduceSigmaPx) {
    // Reduced image: sigma_c / 2 in its pixels, of which the binomial contributes 1/2 and the
    // differences 1/2 (variances in reduced px^2, as DifferenceSmoothingSigma counts them).
    const ConstGrayView reduced = ReduceImage(image, scratch.reduced);
    const float sigma_r = 0.5f * config.sigma_px;
    GaussianKernel g0;
    SH_RETURN_IF_ERROR(MakeGaussianKernel(std::sqrt(sigma_r * sigma_r - 0.5f), 0, g0));
    const ResponseRing resp{scratch.response, reduced.width, reduced.height};
    const float scale = CornerResponseScale(sigma_r);
    // The neighbourhood halves with the pixels (at least the 8 neighbours).
    const int nms_radius = std::max(1, (config.nms_radius_px + 1) / 2);
    return CornersInTwoPasses(image, config, resp, nms_radius, 2, corners, stats,
                              [&](auto&& on_row, float& max_strength) {
                                max_strength =
                                    SmoothedResponse(reduced, g0, scale, scratch, resp, on_row);
                                return Status::Ok();
                              });
  }
  const ResponseRing resp{scratch.response, w, h};
  const Status s = CornersInTwoPasses(image, config, resp, config.nms_radius_px, 1, corners, stats,
                                      [&](auto&& on_row, float& max_strength) {
                                        return FullSizeResponse(image, config, scratch, resp,
                                                                max_strength, on_row);
                                      });
  if (!s.ok()) corners.clear();
  return s;
}

Status CornerResponse(const ConstGrayView& image, const CornerConfig& config,
                      FilterScratch& scratch, ImageView<float> response, float* max_strength) {
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "CornerResponse"));
  SH_RETURN_IF_ERROR(ValidateCornerConfig(config));
  SH_RETURN_IF_ERROR(CheckFitsWorkspace(image.width, image.height, scratch.block(),
                                        "CornerResponse (filter scratch)"));
  if (response.width != image.width || response.height != image.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "CornerResponse: plane %dx%d for an image of %dx%d", response.width,
                         response.height, image.width, image.height);
  }
  const ResponseRing resp{scratch.response, image.width, image.height};
  float max = 0.0f;
  SH_RETURN_IF_ERROR(FullSizeResponse(image, config, scratch, resp, max, [&](int y) {
    std::copy(resp.row(y), resp.row(y) + image.width, response.row(y));
  }));
  if (max_strength != nullptr) *max_strength = max;
  return Status::Ok();
}

}  // namespace sh
