#include "recog/image/canny.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/base/angles.hpp"

namespace sh {

namespace {

constexpr uint8_t kNotEdge = 0;
constexpr uint8_t kWeak = 1;
constexpr uint8_t kStrongPending = 2;

// Texture mode's candidate flags until ClassifyByTexture: the magnitude code (1 .. 127) and
// whether the global high threshold is met.
constexpr uint8_t kGlobalStrongBit = 0x80;
constexpr uint8_t kCodeMask = 0x7f;

// Squared gradient magnitude to its code: the float's exponent and two mantissa bits, four steps
// per octave of the square (eight of the magnitude), code 1 at and below 2^-9. Monotonic.
inline int MagnitudeCode(float magnitude2) {
  uint32_t bits;
  std::memcpy(&bits, &magnitude2, sizeof(bits));
  constexpr int kBase = (127 - 9) << 2;
  const int code = static_cast<int>(bits >> 21) - kBase;
  return std::clamp(code, 1, kTextureCodes - 1);
}

// Steps of MagnitudeCode for a magnitude ratio (eight per octave).
int CodeSteps(float ratio) { return static_cast<int>(std::lround(8.0 * std::log2(ratio))); }

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
  if (!(config.texture_factor >= 0.0f && config.texture_factor <= 64.0f)) {
    return Status::Error(StatusCode::kOutOfRange, "Canny texture factor %g outside [0, 64]",
                         static_cast<double>(config.texture_factor));
  }
  if (!(config.low_threshold > 0.0f) || !(config.high_threshold >= config.low_threshold)) {
    return Status::Error(
        StatusCode::kInvalidArgument, "Canny thresholds need 0 < low <= high, got low %g high %g",
        static_cast<double>(config.low_threshold), static_cast<double>(config.high_threshold));
  }
  return Status::Ok();
}

EdgeTracer::EdgeTracer(const CannyConfig& config, EdgeBuffers& buffers, int width, int height)
    : b_(buffers),
      width_(width),
      height_(height),
      low2_(config.low_threshold * config.low_threshold),
      high2_(config.high_threshold * config.high_threshold),
      texture_(config.texture_factor > 0.0f) {
  if (texture_) {
    texture_low_steps_ = CodeSteps(config.texture_factor);
    texture_high_steps_ =
        texture_low_steps_ + CodeSteps(config.high_threshold / config.low_threshold);
    // MeasureTextureRow clears each block row it measures; a tracer dropped part-way through
    // an image (a failed caller) would leave its last rows' counts behind.
    std::memset(b_.texture_hist, 0, sizeof(b_.texture_hist));
  }
}

void EdgeTracer::CountTexture(int y, const float* magnitude2) {
  if ((y & 1) != 0) return;
  for (int x = 1; x < width_ - 1; x += 2) {
    ++b_.texture_hist[x / kTextureBlockPx][MagnitudeCode(magnitude2[x])];
  }
}

void EdgeTracer::MeasureTextureRow(int block_row) {
  // Fewer samples than a quarter block (a sliver at the image's edge) measure nothing.
  constexpr int kMinSamples = kTextureBlockPx * kTextureBlockPx / 16;
  const int blocks = (width_ + kTextureBlockPx - 1) / kTextureBlockPx;
  for (int bx = 0; bx < blocks; ++bx) {
    uint16_t* hist = b_.texture_hist[bx];
    int total = 0;
    for (int c = 0; c < kTextureCodes; ++c) total += hist[c];
    int quartile = 0;
    if (total >= kMinSamples) {
      for (int seen = 0; quartile < kTextureCodes - 1; ++quartile) {
        seen += hist[quartile];
        if (4 * seen >= total) break;
      }
    }
    b_.texture_code[block_row][bx] = static_cast<uint8_t>(quartile);
    std::memset(hist, 0, sizeof(b_.texture_hist[0]));
  }
}

void EdgeTracer::SpreadTexture() {
  const int bw = (width_ + kTextureBlockPx - 1) / kTextureBlockPx;
  const int bh = (height_ + kTextureBlockPx - 1) / kTextureBlockPx;
  const int global_low_code = MagnitudeCode(low2_);
  texture_blocks_ = static_cast<size_t>(bw) * static_cast<size_t>(bh);
  for (int by = 0; by < bh; ++by) {
    for (int bx = 0; bx < bw; ++bx) {
      int least = kTextureCodes;
      for (int j = std::max(0, by - 1); j <= std::min(bh - 1, by + 1); ++j) {
        for (int i = std::max(0, bx - 1); i <= std::min(bw - 1, bx + 1); ++i) {
          least = std::min<int>(least, b_.texture_code[j][i]);
        }
      }
      // Only a level that raises the low threshold is kept (0: the global thresholds alone), so
      // that below it the edge map is exactly that without the test.
      const bool raised = least > 0 && least + texture_low_steps_ > global_low_code;
      b_.texture_level[by][bx] = static_cast<uint8_t>(raised ? least : 0);
      textured_blocks_ += raised;
    }
  }
}

void EdgeTracer::ClassifyByTexture() {
  const int w = width_;
  SpreadTexture();
  for (int y = 1; y < height_ - 1; ++y) {
    uint8_t* f = b_.edge + static_cast<size_t>(y) * w;
    const uint8_t* quartile = b_.texture_level[y / kTextureBlockPx];
    for (int x = 1; x < w - 1; ++x) {
      const uint8_t flag = f[x];
      if (flag == kNotEdge) continue;
      const int code = flag & kCodeMask;
      const int q = quartile[x / kTextureBlockPx];
      // A block whose texture is below the noise (q 0) leaves the global thresholds alone.
      if (q > 0 && code < q + texture_low_steps_) {
        f[x] = kNotEdge;
        ++texture_dropped_;
        continue;
      }
      if ((flag & kGlobalStrongBit) != 0 && (q == 0 || code >= q + texture_high_steps_)) {
        f[x] = kStrongPending;
        Push(static_cast<uint32_t>(y) * w + x);
      } else {
        f[x] = kWeak;
      }
    }
  }
}

void EdgeTracer::AddRow(const float* __restrict gx, const float* __restrict gy) {
  const int slot = rows_ % 3;
  float* __restrict rx = b_.ring_gx[slot];
  float* __restrict ry = b_.ring_gy[slot];
  float* __restrict m = b_.ring_mag[slot];
  // Squared magnitude: monotonic, so no square roots are needed.
  for (int x = 0; x < width_; ++x) {
    rx[x] = gx[x];
    ry[x] = gy[x];
    m[x] = gx[x] * gx[x] + gy[x] * gy[x];
  }
  if (texture_) {
    CountTexture(rows_, m);
    if ((rows_ + 1) % kTextureBlockPx == 0) MeasureTextureRow(rows_ / kTextureBlockPx);
  }
  ++rows_;
  // Row rows_ - 2 now has both neighbours; the border rows are never edges.
  if (rows_ >= 3) Suppress(rows_ - 2);
}

void EdgeTracer::Suppress(int yc) {
  const int w = width_;
  const float* m = b_.ring_mag[yc % 3];
  const float* mu = b_.ring_mag[(yc - 1) % 3];
  const float* md = b_.ring_mag[(yc + 1) % 3];
  const float* ax = b_.ring_gx[yc % 3];
  const float* ay = b_.ring_gy[yc % 3];
  uint8_t* f = b_.edge + static_cast<size_t>(yc) * w;
  uint8_t* o = b_.orientation + static_cast<size_t>(yc) * w;
  std::fill(f, f + w, kNotEdge);
  // Members in locals: the byte stores below could alias them, which would force a reload or a
  // store of each per pixel.
  const float low2 = low2_, high2 = high2_;
  uint32_t* const stack = b_.stack;
  const size_t capacity = b_.stack_capacity;
  size_t candidates = candidates_, top = top_;
  bool list_was_full = list_was_full_;
  // tan(22.5 deg): splits gradient directions into horizontal, vertical and the two diagonals.
  constexpr float kTan22 = 0.41421356f;
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
    // Orientation now, while the gradient is at hand; Finish clears it where no edge remains.
    o[x] = QuantizeOrientation(std::atan2(ay[x], ax[x]));
    if (texture_) {
      // Classified when the blocks are measured (ClassifyByTexture).
      f[x] = static_cast<uint8_t>(MagnitudeCode(v) | (v >= high2 ? kGlobalStrongBit : 0));
    } else if (v >= high2) {
      // Marked first: when the list is full the mark alone keeps it for Finish's sweeps.
      f[x] = kStrongPending;
      if (top < capacity) {
        stack[top++] = static_cast<uint32_t>(yc) * w + x;
      } else {
        list_was_full = true;
      }
    } else {
      f[x] = kWeak;
    }
  }
  candidates_ = candidates;
  top_ = top;
  list_was_full_ = list_was_full;
}

void EdgeTracer::Push(uint32_t index) {
  if (top_ < b_.stack_capacity) {
    b_.stack[top_++] = index;
  } else {
    list_was_full_ = true;
  }
}

void EdgeTracer::Drain() {
  const int w = width_, h = height_;
  uint8_t* const flag = b_.edge;
  while (top_ > 0) {
    const uint32_t idx = b_.stack[--top_];
    flag[idx] = kEdgePixel;
    ++edge_count_;
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
          Push(n);
        }
      }
    }
  }
}

size_t EdgeTracer::Sweep() {
  const int w = width_, h = height_;
  const uint8_t* const flag = b_.edge;
  size_t sweeps = 0;
  bool forward = true;
  // A sweep during which the list never fills expands every pixel marked before it and marks no
  // new one without expanding it, so none is left.
  while (list_was_full_) {
    list_was_full_ = false;
    ++sweeps;
    for (int i = 1; i < h - 1; ++i) {
      const int y = forward ? i : h - 1 - i;
      for (int j = 1; j < w - 1; ++j) {
        const uint32_t idx = static_cast<uint32_t>(y) * w + (forward ? j : w - 1 - j);
        if (flag[idx] != kStrongPending) continue;
        Push(idx);  // the list is empty here and holds at least one entry
        Drain();
      }
    }
    forward = !forward;
  }
  return sweeps;
}

void EdgeTracer::Finish(EdgeMapView& edges, CannyStats* stats) {
  const int w = width_, h = height_;
  uint8_t* const flag = b_.edge;
  std::fill(flag, flag + w, kNotEdge);
  std::fill(flag + static_cast<size_t>(h - 1) * w, flag + static_cast<size_t>(h) * w, kNotEdge);
  // Hysteresis: grow from strong pixels through 8-connected weak ones. A pixel is marked before
  // it is pushed, so each is expanded once; what did not fit in the list is left to the sweeps.
  // The edge pixels are the weak and strong ones connected to a strong one, whatever the order
  // of expansion, so the map is the same with or without sweeps.
  if (texture_) {
    if (h % kTextureBlockPx != 0) MeasureTextureRow(h / kTextureBlockPx);
    ClassifyByTexture();
  }
  Drain();
  const size_t sweeps = list_was_full_ ? Sweep() : 0;
  // Drop unconnected weak pixels, and the orientation wherever no edge remains. A mask instead of
  // a branch or a select, so that the loop vectorises (kEdgePixel is all ones).
  static_assert(kEdgePixel == 0xff && kNotEdge == 0, "edge flags double as masks");
  uint8_t* __restrict f = flag;
  uint8_t* __restrict o = b_.orientation;
  const size_t n = static_cast<size_t>(w) * h;
  for (size_t i = 0; i < n; ++i) {
    const uint8_t mask = static_cast<uint8_t>(-static_cast<int>(f[i] == kEdgePixel));
    f[i] = mask;
    o[i] = static_cast<uint8_t>(o[i] & mask);
  }
  edges = b_.view(w, h);
  if (stats != nullptr) {
    stats->edge_pixels = edge_count_;
    stats->nms_candidates = candidates_;
    stats->hysteresis_sweeps = sweeps;
    stats->textured_blocks = textured_blocks_;
    stats->texture_blocks = texture_blocks_;
    stats->texture_dropped = texture_dropped_;
  }
}

namespace {

size_t WorkListEntries(size_t pixels, size_t work_list_capacity) {
  return std::max<size_t>(1, std::min(pixels, work_list_capacity));
}

}  // namespace

size_t EdgeBuffers::BytesFor(int width, int height, size_t work_list_capacity) {
  const size_t pixels = size_t{static_cast<size_t>(width)} * static_cast<size_t>(height);
  return 2 * InitBlock::PieceBytes<uint8_t>(pixels) +
         InitBlock::PieceBytes<uint32_t>(WorkListEntries(pixels, work_list_capacity));
}

Status EdgeBuffers::Init(int width, int height, size_t work_list_capacity) {
  const size_t pixels = size_t{static_cast<size_t>(width)} * static_cast<size_t>(height);
  const size_t entries = WorkListEntries(pixels, work_list_capacity);
  if (block_.Holds(width, height) && stack_capacity == entries) return Status::Ok();
  SH_RETURN_IF_ERROR(
      block_.Allocate(width, height, BytesFor(width, height, work_list_capacity), "edge buffers"));
  edge = block_.Take<uint8_t>(pixels);
  orientation = block_.Take<uint8_t>(pixels);
  stack = block_.Take<uint32_t>(entries);
  stack_capacity = entries;
  return Status::Ok();
}

Status DetectEdges(const ConstGrayView& image, const CannyConfig& config, FilterScratch& scratch,
                   EdgeBuffers& buffers, EdgeMapView& edges, CannyStats* stats) {
  edges = EdgeMapView{};
  if (stats != nullptr) *stats = CannyStats{};
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "DetectEdges"));
  SH_RETURN_IF_ERROR(ValidateCannyConfig(config));
  SH_RETURN_IF_ERROR(CheckFitsWorkspace(image.width, image.height, scratch.block(),
                                        "DetectEdges (filter scratch)"));
  SH_RETURN_IF_ERROR(
      CheckFitsWorkspace(image.width, image.height, buffers.block(), "DetectEdges (edge buffers)"));
  GaussianKernel g0, g1;
  SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 0, g0));
  SH_RETURN_IF_ERROR(MakeGaussianKernel(config.sigma_px, 1, g1));
  const int w = image.width, h = image.height;
  const int r = std::max(g0.radius, g1.radius);
  // Row bands (RowBand): ring 0 holds G0 along x, ring 1 G1 along x, filled as the column filters
  // of row y need them; the column filters of row y go straight to the tracer, which suppresses
  // one row behind. No image-sized float planes.
  RowBand band(image, scratch, &g0, &g1);
  EdgeTracer tracer(config, buffers, w, h);
  const float* rows[2 * kMaxGaussianRadius + 1];
  float gx[kMaxImageWidth], gy[kMaxImageWidth];
  for (int y = 0; y < h; ++y) {
    band.FillTo(y + r);
    band.RowPointers(1, y, g0.radius, rows);
    FilterColumnRowFrom(rows, g0, w, gx);
    band.RowPointers(0, y, g1.radius, rows);
    FilterColumnRowFrom(rows, g1, w, gy);
    tracer.AddRow(gx, gy);
  }
  tracer.Finish(edges, stats);
  return Status::Ok();
}

}  // namespace sh
