#include "recog/texture/descriptor.hpp"

#include <algorithm>
#include <cmath>

#include "recog/base/angles.hpp"

namespace sh::texture {
namespace {

constexpr float kTwoPi = 2.0f * kPi;

// Sampling grid of the descriptor, fixed in the point's frame: sample (i, j) sits at
// (i - 7.5, j - 7.5) level pixels from the point; its Gaussian weight and its cell coordinates
// (cell centres at 0 .. 3) do not depend on the image, so they are computed once.
struct DescriptorGrid {
  static constexpr int kN = kDescriptorWindowPx;
  float offset[kN] = {};      // i - 7.5
  float weight[kN][kN] = {};  // exp(-(x^2 + y^2) / (2 (window / 2)^2))
  int cell0[kN] = {};         // floor of the cell coordinate (-1 .. 3)
  float cell_frac[kN] = {};   // its fractional part
  // Per sample: the four cells it spreads into (offsets into the padded histogram of
  // (kC + 2)^2 cells x 8 orientations) and the Gaussian-weighted bilinear spatial weights.
  int cell_offset[kN * kN][4] = {};
  float cell_weight[kN * kN][4] = {};
  DescriptorGrid() {
    const float half = 0.5f * kN;
    const float inv_two_sigma2 = 1.0f / (2.0f * half * half);
    for (int i = 0; i < kN; ++i) {
      offset[i] = static_cast<float>(i) - (half - 0.5f);
      const float c = (static_cast<float>(i) + 0.5f) / kDescriptorCellPx - 0.5f;
      cell0[i] = static_cast<int>(std::floor(c));
      cell_frac[i] = c - static_cast<float>(cell0[i]);
    }
    constexpr int kPadded = kDescriptorCells + 2;
    constexpr int kO = kDescriptorOrientations;
    for (int j = 0; j < kN; ++j) {
      for (int i = 0; i < kN; ++i) {
        weight[j][i] = std::exp(-(offset[i] * offset[i] + offset[j] * offset[j]) * inv_two_sigma2);
        const int k = j * kN + i;
        const int cx = cell0[i] + 1, cy = cell0[j] + 1;  // padded cell indices
        const float fx = cell_frac[i], fy = cell_frac[j];
        cell_offset[k][0] = (cy * kPadded + cx) * kO;
        cell_offset[k][1] = (cy * kPadded + cx + 1) * kO;
        cell_offset[k][2] = ((cy + 1) * kPadded + cx) * kO;
        cell_offset[k][3] = ((cy + 1) * kPadded + cx + 1) * kO;
        cell_weight[k][0] = weight[j][i] * (1.0f - fx) * (1.0f - fy);
        cell_weight[k][1] = weight[j][i] * fx * (1.0f - fy);
        cell_weight[k][2] = weight[j][i] * (1.0f - fx) * fy;
        cell_weight[k][3] = weight[j][i] * fx * fy;
      }
    }
  }
};

const DescriptorGrid& Grid() {
  static const DescriptorGrid grid;  // constant tables, built on first use (no heap)
  return grid;
}

float WrapAngle(float a) {
  while (a > kPi) a -= kTwoPi;
  while (a <= -kPi) a += kTwoPi;
  return a;
}

}  // namespace

float FastAtan2(float y, float x) {
  // Minimax polynomial for atan on [0, 1] (absolute error about 1e-5 rad) of the smaller over
  // the larger component, then the octant. No branches: loops over arrays of gradients that
  // call it vectorise.
  const float ax = std::fabs(x);
  const float ay = std::fabs(y);
  const float z = std::min(ax, ay) / (std::max(ax, ay) + 1e-30f);
  const float z2 = z * z;
  float a =
      z *
      (0.99997726f +
       z2 * (-0.33262347f +
             z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f + z2 * -0.01172120f)))));
  a = ay > ax ? 0.5f * kPi - a : a;
  a = x < 0.0f ? kPi - a : a;
  return std::copysign(a, y);
}

int DescriptorBorderPx() {
  // Farthest sample: the grid's corner turned by 45 degrees, plus one pixel for the bilinear
  // neighbours and one for the central differences of the gradient planes.
  const float corner = 0.5f * (kDescriptorWindowPx - 1) * 1.41421356f;
  return static_cast<int>(std::ceil(corner)) + 2;
}

void MakeOrientationWindow(const OrientationConfig& config, OrientationWindow* window) {
  *window = OrientationWindow{};
  const int radius =
      std::min(kMaxOrientationRadius, static_cast<int>(std::ceil(3.0f * config.sigma_px)));
  window->radius = radius;
  const float inv_two_sigma2 = 1.0f / (2.0f * config.sigma_px * config.sigma_px);
  for (int dy = -radius; dy <= radius; ++dy) {
    for (int dx = -radius; dx <= radius; ++dx) {
      const int r2 = dx * dx + dy * dy;
      if (r2 > radius * radius) continue;
      window->weight[dy + kMaxOrientationRadius][dx + kMaxOrientationRadius] =
          std::exp(-static_cast<float>(r2) * inv_two_sigma2);
    }
  }
}

int DominantOrientations(const ConstFloatView& gx, const ConstFloatView& gy, float x, float y,
                         const OrientationConfig& config, const OrientationWindow& window,
                         float* angles_rad) {
  float hist[kOrientationBins] = {};
  const int radius = window.radius;
  const int cx = static_cast<int>(std::lround(x));
  const int cy = static_cast<int>(std::lround(y));
  constexpr float kBinsPerRad = kOrientationBins / kTwoPi;
  const int x_lo = std::max(-radius, -cx), x_hi = std::min(radius, gx.width - 1 - cx);
  const int n_row = x_hi - x_lo + 1;
  // Per row: weights and bins in a loop that vectorises, then the histogram.
  float w[2 * kMaxOrientationRadius + 1], bin[2 * kMaxOrientationRadius + 1];
  for (int dy = -radius; dy <= radius && n_row > 0; ++dy) {
    const int py = cy + dy;
    if (py < 0 || py >= gx.height) continue;
    const float* rx = gx.row(py) + cx + x_lo;
    const float* ry = gy.row(py) + cx + x_lo;
    const float* wrow = window.weight[dy + kMaxOrientationRadius] + kMaxOrientationRadius + x_lo;
    for (int i = 0; i < n_row; ++i) {
      w[i] = std::sqrt(rx[i] * rx[i] + ry[i] * ry[i]) * wrow[i];
      const float b = FastAtan2(ry[i], rx[i]) * kBinsPerRad;  // [-18, 18]
      bin[i] = b < 0.0f ? b + kOrientationBins : b;
    }
    for (int i = 0; i < n_row; ++i) {
      if (w[i] == 0.0f) continue;
      const int b0 = static_cast<int>(bin[i]);
      const float f = bin[i] - static_cast<float>(b0);
      hist[b0 % kOrientationBins] += w[i] * (1.0f - f);
      hist[(b0 + 1) % kOrientationBins] += w[i] * f;
    }
  }
  // Two passes of the circular (1/4, 1/2, 1/4) kernel.
  for (int pass = 0; pass < 2; ++pass) {
    float smoothed[kOrientationBins];
    for (int b = 0; b < kOrientationBins; ++b) {
      const float prev = hist[(b + kOrientationBins - 1) % kOrientationBins];
      const float next = hist[(b + 1) % kOrientationBins];
      smoothed[b] = 0.25f * prev + 0.5f * hist[b] + 0.25f * next;
    }
    std::copy(smoothed, smoothed + kOrientationBins, hist);
  }
  float peak = 0.0f;
  for (float h : hist) peak = std::max(peak, h);
  if (peak <= 0.0f) return 0;
  // Local maxima above the ratio, strongest first.
  struct Peak {
    float value, angle;
  };
  Peak peaks[kOrientationBins];
  int n_peaks = 0;
  for (int b = 0; b < kOrientationBins; ++b) {
    const float prev = hist[(b + kOrientationBins - 1) % kOrientationBins];
    const float next = hist[(b + 1) % kOrientationBins];
    const float h = hist[b];
    if (h < config.secondary_ratio * peak || h <= prev || h < next) continue;
    const float denom = prev - 2.0f * h + next;
    const float offset = denom < 0.0f ? 0.5f * (prev - next) / denom : 0.0f;  // in (-0.5, 0.5]
    const float a = (static_cast<float>(b) + offset) / kBinsPerRad;
    peaks[n_peaks++] = {h, WrapAngle(a)};
  }
  std::sort(peaks, peaks + n_peaks, [](const Peak& a, const Peak& b) { return a.value > b.value; });
  const int n = std::min({n_peaks, config.max_orientations, kMaxPointOrientations});
  for (int i = 0; i < n; ++i) angles_rad[i] = peaks[i].angle;
  return n;
}

void ComputeDescriptor(const ConstFloatView& gx, const ConstFloatView& gy, float x, float y,
                       float angle_rad, TextureDescriptor* out) {
  const DescriptorGrid& g = Grid();
  constexpr int kC = kDescriptorCells;
  constexpr int kO = kDescriptorOrientations;
  // Cells -1 .. kC along each side so that the trilinear spread needs no bounds checks; only
  // cells 0 .. kC - 1 are kept.
  float hist[kC + 2][kC + 2][kO] = {};
  const float c = std::cos(angle_rad);
  const float s = std::sin(angle_rad);
  constexpr float kBinsPerRad = kO / kTwoPi;
  constexpr int kN = DescriptorGrid::kN;
  constexpr int kSamples = kN * kN;
  // 1. Gradients at the turned grid's samples (bilinear, no clamping: the caller keeps the grid
  // inside the planes).
  float sgx[kSamples], sgy[kSamples];
  for (int j = 0; j < kN; ++j) {
    const float ly = g.offset[j];
    for (int i = 0; i < kN; ++i) {
      const float lx = g.offset[i];
      const float px = x + c * lx - s * ly;
      const float py = y + s * lx + c * ly;
      const int x0 = static_cast<int>(px);
      const int y0 = static_cast<int>(py);
      const float fx = px - static_cast<float>(x0);
      const float fy = py - static_cast<float>(y0);
      const float w00 = (1.0f - fx) * (1.0f - fy), w01 = fx * (1.0f - fy);
      const float w10 = (1.0f - fx) * fy, w11 = fx * fy;
      const float* ax = gx.row(y0) + x0;
      const float* bx = ax + gx.stride;
      const float* ay = gy.row(y0) + x0;
      const float* by = ay + gy.stride;
      sgx[j * kN + i] = w00 * ax[0] + w01 * ax[1] + w10 * bx[0] + w11 * bx[1];
      sgy[j * kN + i] = w00 * ay[0] + w01 * ay[1] + w10 * by[0] + w11 * by[1];
    }
  }
  // 2. Magnitudes and orientation bins in the point's frame (vectorises).
  float mag[kSamples], ori[kSamples];
  for (int k = 0; k < kSamples; ++k) {
    const float rx = c * sgx[k] + s * sgy[k];
    const float ry = -s * sgx[k] + c * sgy[k];
    mag[k] = std::sqrt(rx * rx + ry * ry);
    const float o = FastAtan2(ry, rx) * kBinsPerRad;  // [-4, 4]
    ori[k] = o < 0.0f ? o + kO : o;
  }
  // 3. Trilinear spread into cells x orientations (spatial weights from the grid's tables).
  float* h = &hist[0][0][0];
  for (int k = 0; k < kSamples; ++k) {
    const float m = mag[k];
    if (m == 0.0f) continue;
    const int o0 = static_cast<int>(ori[k]) & (kO - 1);  // ori may round to exactly kO
    const int o1 = (o0 + 1) & (kO - 1);
    const float fo = ori[k] - static_cast<float>(static_cast<int>(ori[k]));
    const float m1 = m * fo, m0 = m - m1;
    for (int q = 0; q < 4; ++q) {
      float* cell = h + g.cell_offset[k][q];
      cell[o0] += m0 * g.cell_weight[k][q];
      cell[o1] += m1 * g.cell_weight[k][q];
    }
  }
  float v[kDescriptorSize];
  int k = 0;
  for (int cy = 1; cy <= kC; ++cy) {
    for (int cx = 1; cx <= kC; ++cx) {
      for (int o = 0; o < kO; ++o) v[k++] = hist[cy][cx][o];
    }
  }
  // Lowe's normalisation: unit length, clip large components (non-linear illumination effects
  // on a few gradients), unit length again.
  float norm2 = 0.0f;
  for (float e : v) norm2 += e * e;
  if (norm2 <= 0.0f) {
    *out = TextureDescriptor{};
    return;
  }
  float inv = 1.0f / std::sqrt(norm2);
  norm2 = 0.0f;
  for (float& e : v) {
    e = std::min(e * inv, 0.2f);
    norm2 += e * e;
  }
  inv = 512.0f / std::sqrt(norm2);
  for (int i = 0; i < kDescriptorSize; ++i) {
    out->v[i] = static_cast<uint8_t>(std::min(255.0f, v[i] * inv + 0.5f));  // rounded
  }
}

}  // namespace sh::texture
