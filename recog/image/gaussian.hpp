// Separable Gaussian and Gaussian-derivative filtering of grey images.
//
// Filters are sampled Gaussians (and their first/second derivatives) truncated at ~3 sigma and
// applied as correlations `out(x) = sum_k in(x + k) * tap[k]`, so a first-derivative filter
// estimates d/dx (positive for intensity increasing towards +x). Borders replicate the edge
// pixel. Arithmetic is float: the per-pixel cost is dominated by the taps, and float keeps the
// inner loops simple enough for the compiler to vectorise (SSE/NEON) without intrinsics.
#pragma once

#include <cstdint>

#include "recog/base/init_block.hpp"
#include "recog/base/status.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/image/image.hpp"

namespace sh {

// Largest kernel radius, in pixels. A radius of ceil(3 sigma) keeps > 99.7 % of the Gaussian's
// mass; 24 px covers sigma up to 8 px (the largest corner scale used in practice).
inline constexpr int kMaxGaussianRadius = 24;
inline constexpr float kMaxGaussianSigmaPx = kMaxGaussianRadius / 3.0f;
inline constexpr float kMinGaussianSigmaPx = 0.3f;

// One symmetric (order 0, 2) or antisymmetric (order 1) 1-D kernel. Only taps[0..radius] are
// stored; tap[-k] = tap[k] for even order and -tap[k] for odd order.
struct GaussianKernel {
  int order = 0;
  int radius = 0;
  float sigma_px = 0.0f;
  float taps[kMaxGaussianRadius + 1] = {};
};

// Radius used for a given sigma: ceil(3 sigma), at least 1.
int GaussianRadiusFor(float sigma_px);

// Builds the sampled kernel of the given derivative order (0, 1 or 2). The sampled taps are
// renormalised so that the discrete filter is exact on polynomials: order 0 sums to 1, order 1
// maps the ramp x to 1, order 2 maps a constant to 0 and x^2 / 2 to 1. Fails for sigma outside
// [kMinGaussianSigmaPx, kMaxGaussianSigmaPx] or an unsupported order.
Status MakeGaussianKernel(float sigma_px, int order, GaussianKernel& kernel);

// A float image plane over storage carved at initialisation (FilterScratch::Init); rows are packed
// (stride == width) so the planes of one frame stay contiguous in cache.
struct FloatPlane {
  float* data = nullptr;
  ImageView<float> view(int width, int height) { return {data, width, height, width}; }
  ImageView<const float> view(int width, int height) const { return {data, width, height, width}; }
};

// Pixels of an image reduced 2x in both directions (every second column and row, from 0).
inline constexpr size_t ReducedPixels(int width, int height) {
  return size_t{static_cast<size_t>(width + 1) / 2} * (static_cast<size_t>(height + 1) / 2);
}
inline constexpr size_t kMaxReducedPixels = ReducedPixels(kMaxImageWidth, kMaxImageHeight);

// The size a workspace is initialised for: refuses sizes outside 1 .. kMaxImageWidth x
// kMaxImageHeight, naming `what`.
Status CheckWorkspaceSize(int width, int height, const char* what);

// The block a workspace carves its image buffers from (InitBlock) and the image size it was taken
// for (0 x 0 until then).
class ImageBlock {
 public:
  // For images up to width x height: refuses sizes outside 1x1 .. kMaxImageWidth x
  // kMaxImageHeight (naming `what`), else takes `bytes` (earlier pieces become invalid).
  Status Allocate(int width, int height, size_t bytes, const char* what);
  template <typename T>
  T* Take(size_t count) {
    return block_.Take<T>(count);
  }
  bool Holds(int width, int height) const { return width == width_ && height == height_; }
  uint8_t* data() const { return block_.data(); }
  size_t bytes() const { return block_.bytes(); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  InitBlock block_;
  int width_ = 0, height_ = 0;
};

// Whether an image of width x height fits the buffers of `block`; the error names `what`, both
// sizes, or that the workspace was never initialised.
Status CheckFitsWorkspace(int width, int height, const ImageBlock& block, const char* what);

// Work memory of the detectors of one frame: rings of row-filtered rows (the filters run in row
// bands: a column pass of radius r needs only rows y - r .. y + r of its input, so
// kRingRows = 2 kMaxGaussianRadius + 1 rows of each row-filtered plane replace the whole plane),
// a ring of corner response rows (kResponseRows: a row's corners are taken once the rows within
// the largest NMS radius, 16 px, exist), and the 2x reduced grey image of the large corner
// scales: 3 x 196 W + 33 x 4 W + W H / 4 bytes for images up to W x H, taken at Init (one block,
// docs/memory.md). Keep one per concurrent frame.
struct FilterScratch {
  static constexpr int kRings = 3;
  static constexpr int kRingRows = 2 * kMaxGaussianRadius + 1;
  static constexpr int kResponseRows = 33;
  float* rings[kRings] = {};  // kRingRows rows of the image width each (RowBand)
  float* response = nullptr;  // corner response, kResponseRows rows of the image width
  uint8_t* reduced = nullptr;

  // Bytes Init takes for images up to width x height.
  static size_t BytesFor(int width, int height);
  // Carves the buffers for images up to width x height (at start-up: allocates). A second call
  // with the same size keeps them. EdgeBuffers and HoughWorkspace size themselves the same way.
  // `min_bytes`: the block is at least that large, for a later stage that borrows it whole once
  // the filters are done (FeatureWorkspace: the Hough transform's pixel lists).
  Status Init(int width, int height, size_t min_bytes = 0);
  const ImageBlock& block() const { return block_; }

 private:
  ImageBlock block_;
};

// A workspace (FilterScratch, EdgeBuffers, HoughWorkspace or FeatureWorkspace) on the heap, its
// buffers sized for images up to width x height; null when the size is out of range or memory
// is short. For start-up, tools and tests; the fixed part comes from calloc (MakeZeroed), so its
// untouched pages stay out of resident memory.
template <typename T>
ZeroedPtr<T> MakeWorkspace(int width = kMaxImageWidth, int height = kMaxImageHeight) {
  ZeroedPtr<T> ws = MakeZeroed<T>();
  if (ws == nullptr || !ws->Init(width, height).ok()) return nullptr;
  return ws;
}

// Smoothing scale that, followed by central differences, approximates Gaussian derivatives at
// sigma_px: sqrt(sigma^2 - 1/4), at least kMinGaussianSigmaPx. The differences add a blur of their
// own (variance 1/3 px^2 for the first difference, 1/6 for the second; 1/4 splits them), so one
// smoothing pass replaces the separate derivative filters (the corner detector).
float DifferenceSmoothingSigma(float sigma_px);

// Checks that a grey image is non-empty, consistent, and no larger than the compile-time maximum.
Status ValidateGrayImage(const ConstGrayView& image, const char* what);

// Row (x-direction) pass: convolves each row of `image` with up to three kernels at once, so the
// source row is read once. Outputs may be null to skip a kernel. Output views must have the image
// size.
void FilterRows(const ConstGrayView& image, const GaussianKernel* k0, ImageView<float> out0,
                const GaussianKernel* k1, ImageView<float> out1, const GaussianKernel* k2,
                ImageView<float> out2);

// Pointers to rows y - radius .. y + radius of `in` (rows[k + radius] is row y + k), with rows
// outside the image replaced by the nearest border row. `rows` holds 2 * radius + 1 entries.
void ClampedRowPointers(const ImageView<const float>& in, int y, int radius, const float** rows);

// Column (y-direction) pass of one float plane with one kernel, for output row y only (written to
// out_row, which must not overlap `in`): lets callers consume each filtered row while it is
// still in cache.
void FilterColumnRow(const ImageView<const float>& in, const GaussianKernel& kernel, int y,
                     float* out_row);

// Column pass of one output row from its input rows: rows[k + kernel.radius] is input row y + k
// (k = -radius .. radius). FilterColumnRow and the row bands (RowBand) share it, so a band gives
// the same floats as the whole plane.
void FilterColumnRowFrom(const float* const* rows, const GaussianKernel& kernel, int width,
                         float* out_row);

// An image filtered along x with up to three kernels (as FilterRows), one row at a time into the
// rings of a FilterScratch (ring i for kernel i): row y sits in slot y % kRingRows, so after
// FillTo(y + r) the rows y - r .. y + r of every ring are at hand for a column pass of radius
// r <= kMaxGaussianRadius. Output rows must be produced in increasing y. A ring whose kernel is
// null is free for the caller's own rows (RingRow). The image must fit the scratch.
class RowBand {
 public:
  RowBand(const ConstGrayView& image, FilterScratch& scratch, const GaussianKernel* k0,
          const GaussianKernel* k1 = nullptr, const GaussianKernel* k2 = nullptr);
  // Filters the rows up to min(y, height - 1) that are not filtered yet.
  void FillTo(int y);
  // rows[k + radius] = row clamp(y + k, 0, height - 1) of ring `ring` (FillTo(y + radius) first).
  void RowPointers(int ring, int y, int radius, const float** rows) const;
  // Slot of row y in ring `ring` (width floats).
  float* RingRow(int ring, int y) const {
    return rings_[ring] + static_cast<size_t>(y % FilterScratch::kRingRows) * width_;
  }

 private:
  ConstGrayView image_;
  const GaussianKernel* kernels_[FilterScratch::kRings];
  float* rings_[FilterScratch::kRings];
  int width_ = 0;
  int pad_radius_ = 0;
  int filled_ = 0;  // rows 0 .. filled_ - 1 have been filtered
  float pad_[kMaxImageWidth + 2 * kMaxGaussianRadius];
};

// Column (y-direction) pass of one float plane with one kernel.
void FilterColumns(const ImageView<const float>& in, const GaussianKernel& kernel,
                   ImageView<float> out);

// Convenience for tests and tools: out = (kx along x) then (ky along y) of the image. Uses
// `scratch` for the intermediate plane.
Status GaussianFilter2d(const ConstGrayView& image, float sigma_px, int order_x, int order_y,
                        FloatPlane& scratch, ImageView<float> out);

}  // namespace sh
