// Colour segmentation of one image into connected regions (seed 001 section IV-A): every pixel
// is classified into a part colour (ColourClassifier), horizontal runs of one class are joined
// into 8-connected regions by union-find, and each region keeps what correspondence and the
// view window need: colour, pixel count, bounding box, centroid and its runs.
//
// Statically allocated (about 7 MB per image: the class image, the R'G'B' conversion of
// non-RGB frames, runs); Segment() never allocates. Capacities: kMaxColourRuns runs per image
// (sensor noise on a coloured table could produce more: the rows beyond are not labelled and
// `runs_truncated` says so) and kMaxColourRegions regions of at least min_area_px (the largest are
// kept).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"
#include "recog/shape/colour_classes.hpp"

namespace sh {

inline constexpr size_t kMaxColourRuns = 32768;
inline constexpr size_t kMaxColourRegions = 64;
inline constexpr uint32_t kNoRun = 0xffffffffu;

struct ColourRun {
  uint16_t y = 0;
  uint16_t x0 = 0, x1 = 0;  // pixels [x0, x1)
  uint8_t colour = 0;       // class id
  uint8_t reserved = 0;
  uint32_t parent = 0;     // union-find during labelling
  uint32_t next = kNoRun;  // next run of the same region, in scan order
};

struct ColourRegion {
  uint8_t colour = 0;
  uint32_t area_px = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // inclusive bounding box, pixels
  float cx = 0, cy = 0;                // centroid, pixel centres at integer coordinates
  uint32_t first_run = kNoRun;
  uint32_t n_runs = 0;

  int width() const { return x1 - x0 + 1; }
  int height() const { return y1 - y0 + 1; }
};

struct SegmentConfig {
  // Regions smaller than this are dropped (noise, slivers of parts hidden almost entirely).
  int min_area_px = 150;
};

Status CheckSegmentConfig(const SegmentConfig& config);

class ColourSegmentation {
 public:
  // Classifies and labels one frame (any FrameFormat; grey frames give no regions).
  Status Segment(const FrameView& frame, const ColourClassifier& classifier,
                 const SegmentConfig& config);

  // Class id of every pixel of the last frame (valid until the next Segment()).
  ConstGrayView classes() const { return {classes_, width_, height_, width_}; }
  // The last frame as R'G'B': the frame itself when it is RGB, else its conversion (valid until
  // the next Segment(), and as long as an RGB frame's memory).
  ImageView<const Rgb8> rgb() const { return rgb_view_; }
  const Vector<ColourRun>& runs() const { return runs_; }
  const Vector<ColourRegion>& regions() const { return regions_; }
  bool runs_truncated() const { return runs_truncated_; }
  bool regions_truncated() const { return regions_truncated_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  uint32_t Find(uint32_t i);
  void Label(const ColourClassifier& classifier, const FrameView& frame);
  void CollectRegions(const SegmentConfig& config);

  int width_ = 0, height_ = 0;
  bool runs_truncated_ = false, regions_truncated_ = false;
  uint8_t classes_[kMaxImagePixels];
  Rgb8 rgb_[kMaxImagePixels];  // conversion of non-RGB frames
  ImageView<const Rgb8> rgb_view_;
  Vector<ColourRun, kMaxColourRuns> runs_;
  Vector<ColourRegion, kMaxColourRegions> regions_;
  // Per root run while collecting: area, sums and box of its region.
  struct RootStats {
    uint32_t area;
    int x0, y0, x1, y1;
    double sum_x, sum_y;
    uint32_t last_run;
    int32_t region;
  };
  RootStats root_stats_[kMaxColourRuns];
};

// Writes the mask of `region` (255 inside, 0 outside) into `mask`, whose top-left pixel is image
// pixel (region.x0, region.y0); mask must be at least region.width() x region.height().
void RegionMask(const ColourRegion& region, const Vector<ColourRun>& runs, GrayView mask);

}  // namespace sh
