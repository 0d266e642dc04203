#include "recog/image/gaussian.hpp"

#include <algorithm>
#include <cmath>

namespace sh {

int GaussianRadiusFor(float sigma_px) {
  const int r = static_cast<int>(std::ceil(3.0f * sigma_px - 1e-4f));
  return std::clamp(r, 1, kMaxGaussianRadius);
}

Status MakeGaussianKernel(float sigma_px, int order, GaussianKernel& kernel) {
  if (!(sigma_px >= kMinGaussianSigmaPx && sigma_px <= kMaxGaussianSigmaPx)) {
    return Status::Error(StatusCode::kOutOfRange, "Gaussian sigma %.3f px outside [%.2f, %.2f]",
                         static_cast<double>(sigma_px), static_cast<double>(kMinGaussianSigmaPx),
                         static_cast<double>(kMaxGaussianSigmaPx));
  }
  if (order < 0 || order > 2) {
    return Status::Error(StatusCode::kInvalidArgument, "Gaussian derivative order %d not in 0..2",
                         order);
  }
  kernel = GaussianKernel{};
  kernel.order = order;
  kernel.sigma_px = sigma_px;
  kernel.radius = GaussianRadiusFor(sigma_px);
  const int r = kernel.radius;
  // Work in double: the renormalisation sums are differences of similar numbers for order 2.
  double g[kMaxGaussianRadius + 1];
  double g_sum = 0.0;
  const double s2 = double{sigma_px} * sigma_px;
  for (int k = 0; k <= r; ++k) {
    g[k] = std::exp(-0.5 * k * k / s2);
    g_sum += (k == 0 ? 1.0 : 2.0) * g[k];
  }
  for (int k = 0; k <= r; ++k) g[k] /= g_sum;  // order-0 taps, summing to 1 over -r..r
  double h[kMaxGaussianRadius + 1];
  if (order == 0) {
    for (int k = 0; k <= r; ++k) h[k] = g[k];
  } else if (order == 1) {
    // Antisymmetric: response to the ramp x is sum_k k h[k] over -r..r = 2 sum_{k>0} k h[k].
    double moment = 0.0;
    for (int k = 0; k <= r; ++k) {
      h[k] = k * g[k];
      moment += 2.0 * k * h[k];
    }
    for (int k = 0; k <= r; ++k) h[k] /= moment;
  } else {
    double sum = 0.0;
    for (int k = 0; k <= r; ++k) {
      h[k] = (k * k / s2 - 1.0) * g[k];
      sum += (k == 0 ? 1.0 : 2.0) * h[k];
    }
    // Remove the DC response (truncation leaves some), then scale so x^2/2 maps to 1.
    double moment = 0.0;
    for (int k = 0; k <= r; ++k) {
      h[k] -= sum * g[k];
      moment += (k == 0 ? 0.0 : 2.0) * 0.5 * k * k * h[k];
    }
    for (int k = 0; k <= r; ++k) h[k] /= moment;
  }
  for (int k = 0; k <= r; ++k) kernel.taps[k] = static_cast<float>(h[k]);
  return Status::Ok();
}

float DifferenceSmoothingSigma(float sigma_px) {
  return std::max(kMinGaussianSigmaPx, std::sqrt(std::max(0.0f, sigma_px * sigma_px - 0.25f)));
}

Status CheckWorkspaceSize(int width, int height, const char* what) {
  if (width <= 0 || height <= 0 || width > kMaxImageWidth || height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s: image size %dx%d outside the supported 1x1 .. %dx%d", what, width,
                         height, kMaxImageWidth, kMaxImageHeight);
  }
  return Status::Ok();
}

Status ImageBlock::Allocate(int width, int height, size_t bytes, const char* what) {
  SH_RETURN_IF_ERROR(CheckWorkspaceSize(width, height, what));
  width_ = height_ = 0;
  if (!block_.Allocate(bytes)) {
    return Status::Error(StatusCode::kUnavailable, "%s: cannot allocate %zu bytes for %dx%d", what,
                         bytes, width, height);
  }
  width_ = width;
  height_ = height;
  return Status::Ok();
}

Status CheckFitsWorkspace(int width, int height, const ImageBlock& block, const char* what) {
  if (block.width() == 0) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "%s: workspace not initialised (Init with the camera's image size)", what);
  }
  if (width > block.width() || height > block.height()) {
    return Status::Error(StatusCode::kOutOfRange,
                         "%s: image %dx%d larger than the %dx%d the workspace was initialised for",
                         what, width, height, block.width(), block.height());
  }
  return Status::Ok();
}

size_t FilterScratch::BytesFor(int width, int height) {
  const size_t ring = size_t{kRingRows} * static_cast<size_t>(width);
  return kRings * InitBlock::PieceBytes<float>(ring) +
         InitBlock::PieceBytes<float>(size_t{kResponseRows} * static_cast<size_t>(width)) +
         InitBlock::PieceBytes<uint8_t>(ReducedPixels(width, height));
}

Status FilterScratch::Init(int width, int height, size_t min_bytes) {
  const size_t bytes = std::max(BytesFor(width, height), min_bytes);
  if (block_.Holds(width, height) && block_.bytes() >= bytes) return Status::Ok();
  SH_RETURN_IF_ERROR(block_.Allocate(width, height, bytes, "filter scratch"));
  for (float*& ring : rings) ring = block_.Take<float>(size_t{kRingRows} * width);
  response = block_.Take<float>(size_t{kResponseRows} * width);
  reduced = block_.Take<uint8_t>(ReducedPixels(width, height));
  return Status::Ok();
}

Status ValidateGrayImage(const ConstGrayView& image, const char* what) {
  if (image.data == nullptr || image.width <= 0 || image.height <= 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: empty image (%dx%d, data %s)", what,
                         image.width, image.height, image.data ? "set" : "null");
  }
  if (image.stride < image.width) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: stride %d smaller than width %d", what,
                         image.stride, image.width);
  }
  if (image.width > kMaxImageWidth || image.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange, "%s: image %dx%d larger than the supported %dx%d",
                         what, image.width, image.height, kMaxImageWidth, kMaxImageHeight);
  }
  return Status::Ok();
}

namespace {

// Applies one kernel to a padded row: pad[i] is source column i - pad_radius. The parity is a
// template argument so that the inner loops carry no sign multiply; the sums are formed in the
// same order as the plain definition (centre tap, then tap pairs 1..radius). Looping over the
// taps outermost measured faster here than keeping blocks of sums in registers (the column pass
// below): with restrict the compiler vectorises each tap loop fully.
template <bool kAntisymmetric>
void ConvolvePaddedRowT(const float* __restrict pad, int pad_radius, int width,
                        const GaussianKernel& k, float* __restrict out) {
  const float* center = pad + pad_radius;
  const float t0 = k.taps[0];
  for (int x = 0; x < width; ++x) out[x] = t0 * center[x];
  for (int j = 1; j <= k.radius; ++j) {
    const float t = k.taps[j];
    const float* plus = center + j;
    const float* minus = center - j;
    if (kAntisymmetric) {
      for (int x = 0; x < width; ++x) out[x] += t * (plus[x] - minus[x]);
    } else {
      for (int x = 0; x < width; ++x) out[x] += t * (plus[x] + minus[x]);
    }
  }
}

void ConvolvePaddedRow(const float* pad, int pad_radius, int width, const GaussianKernel& k,
                       float* out) {
  if (k.order == 1) {
    ConvolvePaddedRowT<true>(pad, pad_radius, width, k, out);
  } else {
    ConvolvePaddedRowT<false>(pad, pad_radius, width, k, out);
  }
}

// Column pass of one output row with a symmetric kernel; rows[r + k] is input row y + k. Outputs
// are computed in blocks whose sums stay in registers across all taps, so each tap costs two loads
// and the arithmetic instead of also a load and a store of the output (about 25 % faster than
// looping over the taps outermost). 16 floats are four SSE or NEON registers. The sums are
// formed in the same order as the plain definition (centre tap, then tap pairs 1..radius).
void SymmetricColumnRow(const float* const* rows, int r, const GaussianKernel& kernel, int w,
                        float* __restrict dst) {
  constexpr int kLanes = 16;
  const float t0 = kernel.taps[0];
  int x = 0;
  for (; x + kLanes <= w; x += kLanes) {
    float acc[kLanes];
    const float* c = rows[r] + x;
    for (int i = 0; i < kLanes; ++i) acc[i] = t0 * c[i];
    for (int j = 1; j <= r; ++j) {
      const float t = kernel.taps[j];
      const float* plus = rows[r + j] + x;
      const float* minus = rows[r - j] + x;
      for (int i = 0; i < kLanes; ++i) acc[i] += t * (plus[i] + minus[i]);
    }
    for (int i = 0; i < kLanes; ++i) dst[x + i] = acc[i];
  }
  for (; x < w; ++x) {
    float acc = t0 * rows[r][x];
    for (int j = 1; j <= r; ++j) acc += kernel.taps[j] * (rows[r + j][x] + rows[r - j][x]);
    dst[x] = acc;
  }
}

// Column pass with an antisymmetric kernel, taps outermost: GCC vectorises the blocked form above
// only partly for differences (twice slower here). plus + (-1) * minus of the plain definition
// equals plus - minus exactly. No restrict on purpose: with it GCC fuses pairs of taps into one
// scalar loop instead of vectorising each tap loop.
void AntisymmetricColumnRow(const float* const* rows, int r, const GaussianKernel& kernel, int w,
                            float* dst) {
  const float* c = rows[r];
  const float t0 = kernel.taps[0];
  for (int x = 0; x < w; ++x) dst[x] = t0 * c[x];
  for (int j = 1; j <= r; ++j) {
    const float t = kernel.taps[j];
    const float* plus = rows[r + j];
    const float* minus = rows[r - j];
    for (int x = 0; x < w; ++x) dst[x] += t * (plus[x] - minus[x]);
  }
}

int PadRadius(const GaussianKernel* k0, const GaussianKernel* k1, const GaussianKernel* k2) {
  int pad_radius = 0;
  for (const GaussianKernel* k : {k0, k1, k2}) {
    if (k != nullptr) pad_radius = std::max(pad_radius, k->radius);
  }
  return pad_radius;
}

// Row y of `image` with replicated borders into `pad` (pad_radius on each side), then each
// non-null kernel applied to it. Every output value depends only on its own tap window, so the
// pad width does not change the result.
void FilterOneRow(const ConstGrayView& image, int y, int pad_radius, float* pad,
                  const GaussianKernel* const* kernels, float* const* out) {
  const int w = image.width;
  const uint8_t* src = image.row(y);
  for (int i = 0; i < pad_radius; ++i) pad[i] = src[0];
  for (int x = 0; x < w; ++x) pad[pad_radius + x] = src[x];
  for (int i = 0; i < pad_radius; ++i) pad[pad_radius + w + i] = src[w - 1];
  for (int i = 0; i < FilterScratch::kRings; ++i) {
    if (kernels[i] != nullptr) ConvolvePaddedRow(pad, pad_radius, w, *kernels[i], out[i]);
  }
}

}  // namespace

void FilterRows(const ConstGrayView& image, const GaussianKernel* k0, ImageView<float> out0,
                const GaussianKernel* k1, ImageView<float> out1, const GaussianKernel* k2,
                ImageView<float> out2) {
  const int pad_radius = PadRadius(k0, k1, k2);
  // Row with replicated borders; on the stack, bounded by the compile-time maxima.
  float pad[kMaxImageWidth + 2 * kMaxGaussianRadius];
  const GaussianKernel* const kernels[FilterScratch::kRings] = {k0, k1, k2};
  for (int y = 0; y < image.height; ++y) {
    float* const out[FilterScratch::kRings] = {k0 != nullptr ? out0.row(y) : nullptr,
                                               k1 != nullptr ? out1.row(y) : nullptr,
                                               k2 != nullptr ? out2.row(y) : nullptr};
    FilterOneRow(image, y, pad_radius, pad, kernels, out);
  }
}

RowBand::RowBand(const ConstGrayView& image, FilterScratch& scratch, const GaussianKernel* k0,
                 const GaussianKernel* k1, const GaussianKernel* k2)
    : image_(image),
      kernels_{k0, k1, k2},
      rings_{scratch.rings[0], scratch.rings[1], scratch.rings[2]},
      width_(image.width),
      pad_radius_(PadRadius(k0, k1, k2)) {}

void RowBand::FillTo(int y) {
  const int last = std::min(y, image_.height - 1);
  for (; filled_ <= last; ++filled_) {
    float* const out[FilterScratch::kRings] = {RingRow(0, filled_), RingRow(1, filled_),
                                               RingRow(2, filled_)};
    FilterOneRow(image_, filled_, pad_radius_, pad_, kernels_, out);
  }
}

void RowBand::RowPointers(int ring, int y, int radius, const float** rows) const {
  for (int k = -radius; k <= radius; ++k) {
    rows[k + radius] = RingRow(ring, std::clamp(y + k, 0, image_.height - 1));
  }
}

void ClampedRowPointers(const ImageView<const float>& in, int y, int radius, const float** rows) {
  for (int k = -radius; k <= radius; ++k) {
    rows[k + radius] = in.row(std::clamp(y + k, 0, in.height - 1));
  }
}

void FilterColumnRowFrom(const float* const* rows, const GaussianKernel& kernel, int width,
                         float* out_row) {
  if (kernel.order == 1) {
    AntisymmetricColumnRow(rows, kernel.radius, kernel, width, out_row);
  } else {
    SymmetricColumnRow(rows, kernel.radius, kernel, width, out_row);
  }
}

void FilterColumnRow(const ImageView<const float>& in, const GaussianKernel& kernel, int y,
                     float* out_row) {
  const float* rows[2 * kMaxGaussianRadius + 1];
  ClampedRowPointers(in, y, kernel.radius, rows);
  FilterColumnRowFrom(rows, kernel, in.width, out_row);
}

void FilterColumns(const ImageView<const float>& in, const GaussianKernel& kernel,
                   ImageView<float> out) {
  for (int y = 0; y < in.height; ++y) FilterColumnRow(in, kernel, y, out.row(y));
}

Status GaussianFilter2d(const ConstGrayView& image, float sigma_px, int order_x, int order_y,
                        FloatPlane& scratch, ImageView<float> out) {
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "GaussianFilter2d"));
  if (out.data == nullptr || out.width != image.width || out.height != image.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "GaussianFilter2d: output %dx%d does not match image %dx%d", out.width,
                         out.height, image.width, image.height);
  }
  GaussianKernel kx, ky;
  SH_RETURN_IF_ERROR(MakeGaussianKernel(sigma_px, order_x, kx));
  SH_RETURN_IF_ERROR(MakeGaussianKernel(sigma_px, order_y, ky));
  ImageView<float> tmp = scratch.view(image.width, image.height);
  FilterRows(image, &kx, tmp, nullptr, {}, nullptr, {});
  FilterColumns(tmp, ky, out);
  return Status::Ok();
}

}  // namespace sh
