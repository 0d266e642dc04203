// Straight lines from Canny edge pixels by a Hough transform in
// rho = x sin(theta) + y cos(theta), theta in [0, pi) (method notes section 2):
//  - each edge pixel votes only for theta within angle_window_deg of the line direction implied
//    by its gradient;
//  - votes are spread along rho by a cosine-shaped kernel;
//  - peaks are taken one at a time: the global maximum; the unassigned edge pixels within
//    collect_distance_px of its line (and whose vote window contains it) are assigned to it and
//    their votes removed; repeat until the maximum falls below min_votes. So an edge pixel
//    supports at most one line;
//  - the peak is refined by a quadratic fit to its 3x3 neighbourhood (Niblack & Petkovic), kept
//    at the cell centre when the fit is not a maximum or moves more than max_refine_shift_bins;
//  - the line is then fitted to its pixels by total least squares, which gives sub-pixel
//    accuracy. The fit starts from the longest run of pixels along the line and is iterated with
//    the pixels within support_distance_px, so that a peak that bridges two nearly collinear
//    edges (a few px apart) settles on one of them; the pixels assigned to the line are then
//    collected again around the fitted line;
//  - its support is the set of segments of the line covered by its pixels within
//    support_distance_px, with gaps up to max_gap_px merged and segments shorter than
//    min_segment_px dropped.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/image/gaussian.hpp"
#include "recog/image/image.hpp"

namespace sh {

inline constexpr size_t kMaxLines2d = 512;
inline constexpr size_t kMaxSegmentsPerLine = 16;

// Accumulator geometry. theta: 0.5 degree bins over [0, 180). rho: 1 px bins covering
// [-kMaxImageHeight, diagonal of the largest image], plus the vote kernel's margin.
inline constexpr int kHoughThetaBins = 360;
inline constexpr float kHoughThetaStepRad = 3.14159265358979f / kHoughThetaBins;
inline constexpr int kMaxVoteHalfWidthPx = 4;
inline constexpr int kHoughMaxDiagonalPx = 1660;  // > hypot(kMaxImageWidth, kMaxImageHeight)
inline constexpr int kHoughRhoOffset = kMaxImageHeight + kMaxVoteHalfWidthPx + 2;  // bin of rho 0
inline constexpr int kHoughRhoBins =
    kHoughRhoOffset + kHoughMaxDiagonalPx + kMaxVoteHalfWidthPx + 2;
static_assert(kHoughMaxDiagonalPx * kHoughMaxDiagonalPx >
                  kMaxImageWidth * kMaxImageWidth + kMaxImageHeight * kMaxImageHeight,
              "rho range must cover the image diagonal");

// Edge pixels taken into the transform of a W x H image: an eighth of its pixels. Canny's map is
// one pixel wide: the recorded scenes of ../shared/scenes have at most 4.6 % of their pixels on
// edges (printed cartons; 0.5 to 1.7 % for the other sets, docs/memory.md), so an eighth leaves
// 2.7 times the busiest frame. Further edge pixels (in raster order) are ignored and counted in
// HoughStats::edge_pixels_dropped.
inline constexpr size_t HoughEdgeCapacity(int width, int height) {
  return size_t{static_cast<size_t>(width)} * static_cast<size_t>(height) / 8;
}
inline constexpr size_t kMaxHoughEdgePixels = HoughEdgeCapacity(kMaxImageWidth, kMaxImageHeight);

struct Segment2D {
  float x0 = 0.0f, y0 = 0.0f, x1 = 0.0f, y1 = 0.0f;  // pixel coordinates, ordered along the line
  float length_px() const { return std::hypot(x1 - x0, y1 - y0); }
};

struct Line2D {
  // The infinite line: rho = x sin(theta) + y cos(theta), theta in [0, pi).
  float theta_rad = 0.0f;
  float rho_px = 0.0f;
  // Unit direction (cos theta, -sin theta) and the foot of the perpendicular from the origin,
  // rho * (sin theta, cos theta); segments are ordered along the direction.
  float dir_x = 1.0f, dir_y = 0.0f;
  float point_x_px = 0.0f, point_y_px = 0.0f;
  // Edge-supported parts of the line. When a line has more than kMaxSegmentsPerLine segments the
  // longest are kept (support_length_px still counts all).
  Vector<Segment2D, kMaxSegmentsPerLine> segments;
  float support_length_px = 0.0f;
  int edge_pixels = 0;  // edge pixels assigned to this line (each supports one line only)
  float votes = 0.0f;   // accumulator peak, in edge pixels
  // Signed distance of a point from the line (positive on the side the normal points to).
  float DistancePx(float x, float y) const {
    return x * std::sin(theta_rad) + y * std::cos(theta_rad) - rho_px;
  }
};

struct HoughConfig {
  float angle_window_deg = 10.0f;    // votes within this of the gradient-implied direction
  float vote_half_width_px = 1.5f;   // cosine kernel cos(pi d / (2 w)) for |d| < w along rho
  float min_votes = 20.0f;           // stop when the peak falls below this, in edge pixels
  float collect_distance_px = 2.0f;  // edge pixels this close to a peak's line join it
  float max_refine_shift_bins = 1.0f;
  float support_distance_px = 1.0f;
  float max_gap_px = 3.0f;
  float min_segment_px = 5.0f;
  // A run of collected pixels along the line (gaps <= max_gap_px) whose own direction differs
  // from the line by more than this belongs to an edge crossing the line at a shallow angle; it
  // is left for that edge instead of being assigned here. Runs of fewer than 6 pixels are kept.
  float max_run_angle_deg = 3.0f;
  int min_edge_pixels = 15;  // lines with fewer assigned pixels within support are dropped
  int max_peaks = 4 * static_cast<int>(kMaxLines2d);  // bound on extraction iterations
};

struct HoughStats {
  size_t edge_pixels = 0;          // edge pixels in the transform
  size_t edge_pixels_dropped = 0;  // not taken for lack of capacity
  size_t edge_pixels_assigned = 0;
  size_t peaks_examined = 0;
  size_t peaks_refined = 0;          // peaks where the quadratic interpolation was kept
  size_t lines_rejected = 0;         // peaks whose line failed min_edge_pixels / min_segment_px
  bool stopped_by_capacity = false;  // kMaxLines2d lines found or max_peaks reached
};

// One edge pixel in the transform (sorted by tc, the centre of its theta window).
struct HoughEdgePoint {
  int16_t x = 0, y = 0;
  int16_t tc = 0;     // theta bin of the gradient-implied line
  int16_t line = -1;  // index into the output lines; -1 unassigned, -2 assigned to a rejected peak
};

// Accumulator and edge-pixel arrays for images up to W x H, taken at Init (docs/memory.md): the
// accumulator holds the rho bins such images can vote for (3.25 MiB at 1280 x 800, 3.7 MiB at
// the maximum), the arrays 2 W H bytes. After DetectLines, points[0 .. point_count) tell which
// line each edge pixel supports.
struct HoughWorkspace {
  static constexpr int kBlock = 64;  // rho bins per block of the incremental maximum search
  static constexpr int kBlocks = (kHoughRhoBins + kBlock - 1) / kBlock;
  static constexpr int kSupportBins = 2 * kHoughMaxDiagonalPx + 8;

  // kHoughThetaBins rows of acc_stride rho bins (AccStrideFor), taken at Init. Bin rho_offset is
  // rho 0: kHoughRhoOffset lowered by whole blocks to the least that images up to the
  // workspace's height need (RhoOffsetFor), which shifts every bin and block by the same count
  // and changes no vote, maximum or line.
  int32_t* acc = nullptr;
  int acc_stride = 0;
  int rho_offset = kHoughRhoOffset;
  int32_t acc_lo = 0, acc_hi = 0;  // rho bins [acc_lo, acc_hi) cleared for the current image
  int32_t* AccRow(int t) { return acc + static_cast<ptrdiff_t>(t) * acc_stride; }
  const int32_t* AccRow(int t) const { return acc + static_cast<ptrdiff_t>(t) * acc_stride; }
  int32_t block_max[kHoughThetaBins][kBlocks];
  int16_t block_arg[kHoughThetaBins][kBlocks];
  uint8_t block_dirty[kHoughThetaBins][kBlocks];
  int32_t row_max[kHoughThetaBins];
  int16_t row_arg[kHoughThetaBins];
  uint8_t row_dirty[kHoughThetaBins];
  int32_t theta_start[kHoughThetaBins + 1];  // points with tc == t: [theta_start[t], [t+1])
  // HoughEdgeCapacity(W, H) entries each, taken at Init (one block, docs/memory.md).
  HoughEdgePoint* points = nullptr;
  size_t point_count = 0;
  uint32_t* collected = nullptr;
  uint32_t* subset = nullptr;  // pixels of the current least-squares fit
  // Support: per 1 px bin along the line, the extreme positions of its pixels.
  float support_lo[kSupportBins];
  float support_hi[kSupportBins];
  int32_t support_count[kSupportBins];
  struct Run {
    float t0, t1;                 // extreme pixel positions along the line
    int32_t count;                // pixels in the run
    float sx, sy, sxx, sxy, syy;  // moments of the run's pixels about the line's point
    bool keep;
  };
  Run runs[kSupportBins / 2 + 1];

  // Sized as FilterScratch is (BytesFor, Init).
  static size_t BytesFor(int width, int height);
  Status Init(int width, int height);
  // collected and subset (ScratchBytesFor), which only DetectLines uses, carved from `scratch`
  // instead: memory of at least ScratchBytesFor bytes that no other stage uses while DetectLines
  // runs (FeatureWorkspace: its FilterScratch block, whose filters are done by then). The
  // workspace's own block then holds the accumulator and the points only (OwnBytesFor).
  Status Init(int width, int height, uint8_t* scratch, size_t scratch_bytes);
  static size_t OwnBytesFor(int width, int height);
  static int RhoOffsetFor(int height);
  static int AccStrideFor(int width, int height);
  static size_t ScratchBytesFor(int width, int height);
  const ImageBlock& block() const { return block_; }
  size_t point_capacity() const { return point_capacity_; }

 private:
  // Carves the accumulator and the points from block_ (OwnBytesFor).
  void TakeOwn(int width, int height);

  ImageBlock block_;
  size_t point_capacity_ = 0;
  const uint8_t* borrowed_ = nullptr;  // the scratch of collected and subset, if not block_
};

Status ValidateHoughConfig(const HoughConfig& config);

// Finds lines; `lines` is cleared first and holds them in extraction order (decreasing peak).
// When kMaxLines2d lines are found extraction stops (the strongest are kept).
Status DetectLines(const ConstEdgeMapView& edges, const HoughConfig& config,
                   HoughWorkspace& workspace, Vector<Line2D>& lines, HoughStats* stats = nullptr);

}  // namespace sh
