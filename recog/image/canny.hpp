// Canny edge detection: Gaussian-derivative gradient at sigma, non-maximum suppression across the
// edge, hysteresis between a low and a high gradient-magnitude threshold.
// The result is an EdgeMapView (edge flag 255 / 0 and the gradient orientation, see edge_map.hpp)
// over caller-owned EdgeBuffers.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/init_block.hpp"
#include "recog/base/status.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/image/gaussian.hpp"
#include "recog/image/image.hpp"

namespace sh {

struct CannyConfig {
  float sigma_px = 1.0f;  // Gaussian scale of the gradient
  // Gradient magnitude thresholds in grey levels per pixel. A step of contrast C blurred at
  // sigma has a peak gradient of C / (sqrt(2 pi) sigma), e.g. 20 for C = 50 at sigma 1.
  float low_threshold = 4.0f;
  float high_threshold = 10.0f;
  // Thresholds that rise over texture (0: off). A grained or mottled table is no noise: its
  // gradient is real, and at thresholds set by the sensor noise its every ripple is an edge. In
  // each block of kTextureBlockPx x kTextureBlockPx pixels the lower quartile of the gradient
  // magnitude measures the block's texture (a quartile rather than the median, so that a block
  // crossed by up to three object edges still measures the surface around them). A candidate
  // edge pixel of that block then needs texture_factor x that quartile to be weak and the
  // high/low ratio above it to be strong, besides the global thresholds. Where the texture is
  // weaker than the noise (a plain table, an object's face) the global thresholds rule alone and
  // the edge map is exactly that without this test.
  float texture_factor = 0.0f;
};

// Blocks over which the texture is measured (CannyConfig::texture_factor).
inline constexpr int kTextureBlockPx = 32;
inline constexpr int kMaxTextureBlocksX = (kMaxImageWidth + kTextureBlockPx - 1) / kTextureBlockPx;
inline constexpr int kMaxTextureBlocksY = (kMaxImageHeight + kTextureBlockPx - 1) / kTextureBlockPx;
// Gradient magnitudes in 8 steps per octave (9 %) from 2^-4.5 up: candidate pixels carry theirs
// in the flag plane until the blocks are measured.
inline constexpr int kTextureCodes = 128;

// Entries of the hysteresis work list (256 KiB): strong pixels waiting to be expanded. The
// busiest recorded frame has about 47,000 edge pixels at 1280 x 800 (4.6 % of its pixels,
// docs/memory.md), and the list holds only those not yet expanded. When it is full, a pixel stays
// marked "strong, not yet expanded" in the flag plane and raster sweeps finish the hysteresis
// (EdgeTracer::Finish): the same edge map, at the cost of the sweeps.
inline constexpr size_t kCannyWorkListCapacity = size_t{64} * 1024;

// Output and work memory of one edge map: 2 bytes of output per pixel for images up to W x H and
// the hysteresis work list (at most kCannyWorkListCapacity entries, no more than W x H), taken at
// Init (one block, docs/memory.md), and three rows of gradient for the widest image.
struct EdgeBuffers {
  uint8_t* edge = nullptr;
  uint8_t* orientation = nullptr;
  uint32_t* stack = nullptr;  // hysteresis work list of stack_capacity entries
  size_t stack_capacity = 0;
  // Ring of the last three gradient rows (x, y, squared magnitude) for non-maximum suppression
  // (45 KiB, zeroed at construction).
  float ring_gx[3][kMaxImageWidth] = {};
  float ring_gy[3][kMaxImageWidth] = {};
  float ring_mag[3][kMaxImageWidth] = {};
  // Texture measure (CannyConfig::texture_factor): histograms of magnitude codes for one row of
  // blocks (10.3 KiB), then each block's lower-quartile code and its level (EdgeTracer).
  uint16_t texture_hist[kMaxTextureBlocksX][kTextureCodes] = {};
  uint8_t texture_code[kMaxTextureBlocksY][kMaxTextureBlocksX] = {};
  uint8_t texture_level[kMaxTextureBlocksY][kMaxTextureBlocksX] = {};
  EdgeMapView view(int width, int height) {
    return {{edge, width, height, width}, {orientation, width, height, width}};
  }

  // Sized as FilterScratch is (BytesFor, Init). A work list smaller than the default (tests of
  // the full list) takes `work_list_capacity`, at least 1.
  static size_t BytesFor(int width, int height, size_t work_list_capacity = kCannyWorkListCapacity);
  Status Init(int width, int height, size_t work_list_capacity = kCannyWorkListCapacity);
  const ImageBlock& block() const { return block_; }

 private:
  ImageBlock block_;
};

inline constexpr uint8_t kEdgePixel = 255;

struct CannyStats {
  size_t edge_pixels = 0;
  size_t nms_candidates = 0;     // pixels left by non-maximum suppression above the low threshold
  size_t hysteresis_sweeps = 0;  // raster sweeps taken because the work list was full (0 if never)
  size_t textured_blocks = 0;    // blocks whose texture raised the low threshold
  size_t texture_blocks = 0;     // blocks measured (0: CannyConfig::texture_factor off)
  size_t texture_dropped = 0;    // candidates below their block's texture threshold
};

Status ValidateCannyConfig(const CannyConfig& config);

// Detects edges; on success `edges` views `buffers` with the image's size. Uses rings 0 and 1 of
// `scratch` (row bands). Pixels on the one-pixel image border are never edges (no gradient
// neighbours).
Status DetectEdges(const ConstGrayView& image, const CannyConfig& config, FilterScratch& scratch,
                   EdgeBuffers& buffers, EdgeMapView& edges, CannyStats* stats = nullptr);

// Non-maximum suppression and hysteresis over gradient rows supplied one at a time, top to
// bottom: the second half of DetectEdges. Suppression runs one row behind the input, so each row is
// used while it is still in cache; the gradient orientation is taken at the suppression candidates
// only. The configuration must be valid.
class EdgeTracer {
 public:
  EdgeTracer(const CannyConfig& config, EdgeBuffers& buffers, int width, int height);
  // Gradient of the next row (rows 0 .. height - 1 in order).
  void AddRow(const float* gx, const float* gy);
  // After the last row: hysteresis; `edges` then views the buffers.
  void Finish(EdgeMapView& edges, CannyStats* stats);

 private:
  void Suppress(int y);
  // Pushes a pixel marked strong-pending; when the list is full it stays marked, for the sweeps.
  void Push(uint32_t index);
  // Expands the listed pixels: each becomes an edge pixel and its weak 8-neighbours are pushed.
  void Drain();
  // Raster sweeps, alternately forward and backward, expanding every pixel left marked
  // strong-pending, until a sweep finds the list never full.
  size_t Sweep();
  // Texture mode: counts the magnitude codes of row y (every other pixel of every other row)
  // into its row of blocks, and measures that row of blocks when y ends it.
  void CountTexture(int y, const float* magnitude2);
  void MeasureTextureRow(int block_row);
  // Texture mode, after the last row: candidates below their block's thresholds are dropped,
  // the rest become weak or strong (and pushed).
  void ClassifyByTexture();
  // Each block's texture level: the least quartile code of it and its 8 neighbours, where that
  // raises the low threshold, else 0.
  void SpreadTexture();

  EdgeBuffers& b_;
  int width_, height_;
  float low2_, high2_;
  bool texture_ = false;
  int texture_low_steps_ = 0, texture_high_steps_ = 0;  // above a block's quartile code
  size_t textured_blocks_ = 0, texture_blocks_ = 0, texture_dropped_ = 0;
  int rows_ = 0;
  size_t candidates_ = 0, top_ = 0, edge_count_ = 0;
  bool list_was_full_ = false;
};

// Gradient direction (atan2(gy, gx), any range) to the 256-step orientation of edge_map.hpp.
uint8_t QuantizeOrientation(float gradient_angle_rad);

// Orientation step back to the gradient angle in [0, pi).
float OrientationToAngleRad(uint8_t orientation);

}  // namespace sh
