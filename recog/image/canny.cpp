#include "recog/image/canny.hpp"

#include <algorithm>
#include <cmath>

namespace sh {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr uint8_t kNotEdge = 0;
constexpr uint8_t kWeak = 1;
constexpr uint8_t kStrongPending = 2;

}  // namespace

uint8_t QuantizeOrientation(float gradient_angle_rad) {
  // 256 steps per half turn; the modulo folds opposite gradient directions together.
  const float steps = gradient_angle_rad * (256.0f / kPi);
  int q = static_cast<int>(std::lround(steps)) % 256;
  if (q < 0) q += 256;
  return static_cast<uint8_t>(q);
}

float OrientationToAngleRad(uint8_t orientation) { return orientation * (kPi / 256.0f); }

Status ValidateCannyConfig(const CannyConfig& config) {
  if (!(config.sigma_px >= kMinGaussianSigmaPx && config.sigma_px <= kMaxGaussianSigmaPx)) {
    return Status::Error(StatusCode::kOutOfRange, "Canny sigma %.3f px outside [%.2f, %.2f]",
                         static_cast<double>(config.sigma_px),
                         static_cast<double>(kMinGaussianSigmaPx),
                         static_cast<double>(kMaxGaussianSigmaPx));
  }
  if (!(config.low_threshold > 0.0f) || !(config.high_threshold >= config.low_threshold)) {
    return Status::Error(
        StatusCode::kInvalidArgument, "Canny thresholds need 0 < low <= high, got low %g high %g",
        static_cast<double>(config.low_threshold), static_cast<double>(config.high_threshold));
  }
  return Status::Ok();
}

Status DetectEdges(const ConstGrayView& image, const CannyConfig& config, FilterScratch& scratch,
                   EdgeBuffers& buffers, EdgeMapView& edges, CannyStats* stats) {
  edges = EdgeMapView{};
  if (stats != nullptr) *stats = CannyStats{};
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "DetectEdges"));
  SH_RETURN_IF_ERROR(ValidateCannyConfig(config));
  GaussianKernel g0, g1;
  SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 0, g0));
  SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 1, g1));
  const int w = image.width, h = image.height;
  ImageView<float> smooth_x = scratch.planes[0].view(w, h);  // G0 along x
  ImageView<float> deriv_x = scratch.planes[1].view(w, h);   // G1 along x
  ImageView<float> gx = scratch.planes[2].view(w, h);
  ImageView<float> gy = scratch.planes[3].view(w, h);
  FilterRows(image, &g0, smooth_x, &g1, deriv_x, nullptr, {});

  edges = buffers.view(w, h);
  uint8_t* const flag = buffers.edge;
  std::fill(flag, flag + static_cast<size_t>(w) * h, kNotEdge);
  std::fill(buffers.orientation, buffers.orientation + static_cast<size_t>(w) * h, uint8_t{0});
  const float low2 = config.low_threshold * config.low_threshold;
  const float high2 = config.high_threshold * config.high_threshold;
  // tan(22.5 deg): splits gradient directions into horizontal, vertical and the two diagonals.
  constexpr float kTan22 = 0.41421356f;
  size_t candidates = 0, top = 0;
  // One pass over the rows: the column filters of row y, its squared magnitude (monotonic, so no
  // square roots are needed) into a ring of three rows, and non-maximum suppression of row y - 1,
  // whose neighbours are then complete. The rows are used while they are still in cache.
  float mag_ring[3][kMaxImageWidth];
  for (int y = 0; y < h; ++y) {
    float* ax_row = gx.row(y);
    float* ay_row = gy.row(y);
    FilterColumnRow(deriv_x, g0, y, ax_row);
    FilterColumnRow(smooth_x, g1, y, ay_row);
    float* m_row = mag_ring[y % 3];
    for (int x = 0; x < w; ++x) m_row[x] = ax_row[x] * ax_row[x] + ay_row[x] * ay_row[x];
    const int yc = y - 1;  // row whose suppression is now possible
    if (yc < 1) continue;
    const float* m = mag_ring[yc % 3];
    const float* mu = mag_ring[(yc - 1) % 3];
    const float* md = mag_ring[y % 3];
    const float* ax = gx.row(yc);
    const float* ay = gy.row(yc);
    uint8_t* f = flag + static_cast<size_t>(yc) * w;
    for (int x = 1; x < w - 1; ++x) {
      const float v = m[x];
      if (v < low2) continue;
      const float adx = std::fabs(ax[x]), ady = std::fabs(ay[x]);
      float before, after;  // neighbours against and along the gradient
      if (ady <= kTan22 * adx) {
        before = m[x - 1];
        after = m[x + 1];
      } else if (adx <= kTan22 * ady) {
        before = mu[x];
        after = md[x];
      } else if ((ax[x] > 0.0f) == (ay[x] > 0.0f)) {
        before = mu[x - 1];
        after = md[x + 1];
      } else {
        before = mu[x + 1];
        after = md[x - 1];
      }
      // Asymmetric comparison keeps exactly one pixel of a two-pixel plateau.
      if (!(v > before && v >= after)) continue;
      ++candidates;
      if (v >= high2) {
        f[x] = kStrongPending;
        buffers.stack[top++] = static_cast<uint32_t>(yc) * w + x;
      } else {
        f[x] = kWeak;
      }
    }
  }
  // Hysteresis: grow from strong pixels through 8-connected weak ones. A pixel is marked before
  // it is pushed, so the stack never holds more than the image's pixel count.
  size_t edge_count = 0;
  while (top > 0) {
    const uint32_t idx = buffers.stack[--top];
    flag[idx] = kEdgePixel;
    ++edge_count;
    const int x = static_cast<int>(idx % w), y = static_cast<int>(idx / w);
    for (int dy = -1; dy <= 1; ++dy) {
      const int yy = y + dy;
      if (yy < 1 || yy >= h - 1) continue;
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = x + dx;
        if (xx < 1 || xx >= w - 1) continue;
        const uint32_t n = static_cast<uint32_t>(yy) * w + xx;
        if (flag[n] == kWeak) {
          flag[n] = kStrongPending;
          buffers.stack[top++] = n;
        }
      }
    }
  }
  // Drop unconnected weak pixels; orientation at the edges.
  for (int y = 0; y < h; ++y) {
    uint8_t* f = flag + static_cast<size_t>(y) * w;
    uint8_t* o = buffers.orientation + static_cast<size_t>(y) * w;
    const float* ax = gx.row(y);
    const float* ay = gy.row(y);
    for (int x = 0; x < w; ++x) {
      if (f[x] == kEdgePixel) {
        o[x] = QuantizeOrientation(std::atan2(ay[x], ax[x]));
      } else {
        f[x] = kNotEdge;
      }
    }
  }
  if (stats != nullptr) {
    stats->edge_pixels = edge_count;
    stats->nms_candidates = candidates;
  }
  return Status::Ok();
}

}  // namespace sh
