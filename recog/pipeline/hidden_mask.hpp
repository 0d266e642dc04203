// The image regions of objects already found in a frame by another path (printed cartons, found
// by their print before the polyhedral search runs), hidden from the polyhedral path's features
// (FeatureMask). Each object's region is the convex hull of its edges projected into the image
// with the lens distortion (points sampled along every model edge, so the curved images of
// straight edges are followed), grown by a margin that covers the pose error and the detectors'
// blur. A box-shaped carton's silhouette is convex, so the hull is its silhouette.
//
// A region may also hold discs around the object's projected corners (the one-image rescue's
// mask: its own corners hidden where the pose error puts them off the outline, its neighbours'
// corners next to the outline left in the search).
//
// Statically sized: at most kMaxHiddenObjects regions per image, each at most
// kMaxOutlinePoints + 4 half-planes, and kMaxHiddenDiscs corner discs in all. (recog/shape's
// RasterizeSilhouette is the exact, non-convex silhouette in a full-image pixel buffer; a grown
// convex region is what hiding needs, in a few kB.) The edge map is cleared row by row from each
// region's span on that row, computed from the half-planes, and disc by disc: no per-pixel mask
// buffer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/image/feature_mask.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

// Objects hidden per image; more are not hidden (Add() returns false, the pipeline counts them).
inline constexpr size_t kMaxHiddenObjects = 32;
// Projected edge samples per object: 9 per edge for a box (12 edges), fewer per edge for models
// with more edges, the corners alone past kMaxOutlinePoints / 2 edges.
inline constexpr int kMaxOutlinePoints = 192;
// Corner discs per mask (Add's corner_radius_px), shared by its regions; an object's corners past
// the last free one get no disc (the region itself is still added).
inline constexpr int kMaxHiddenDiscs = 512;

class HiddenMask final : public FeatureMask {
 public:
  void Clear() {
    n_regions_ = 0;
    n_discs_ = 0;
    discs_dropped_ = 0;
  }
  size_t size() const { return n_regions_; }

  // Adds the silhouette of `object` (pose in the left-camera frame) as seen by `view`, grown by
  // margin_px, and (corner_radius_px > 0) discs of that radius around its projected corners.
  // Returns false, adding nothing, when the mask is full, a model point is not in front of the
  // camera, or the outline is degenerate (fewer than three hull vertices).
  bool Add(const ViewCamera& view, const PosedModel& object, float margin_px,
           float corner_radius_px = 0.0f);
  // Corners that found no free disc since Clear (kMaxHiddenDiscs).
  uint32_t discs_dropped() const { return discs_dropped_; }

  bool Hides(float x_px, float y_px) const override;
  uint32_t ClearEdges(EdgeMapView edges) const override;

  // Columns [*x_begin, *x_end) of region i hidden on pixel row y (empty: x_begin >= x_end),
  // clipped to [0, width).
  void RowSpan(size_t i, int y, int width, int* x_begin, int* x_end) const;

 private:
  // Inside: a x + b y <= c for every half-plane (the hull's edges moved out by the margin, and
  // the margin-grown bounding box, which cuts the mitred spikes of sharp hull corners).
  struct Region {
    int n = 0;
    float a[kMaxOutlinePoints + 4];
    float b[kMaxOutlinePoints + 4];
    float c[kMaxOutlinePoints + 4];
    float y_min = 0, y_max = 0;
    // Its corner discs: entries [first_disc, first_disc + n_discs) of disc_x_ and disc_y_.
    int first_disc = 0, n_discs = 0;
    float disc_radius_px = 0;
  };
  // Whether (x, y) lies in one of region r's corner discs.
  bool InDisc(const Region& r, float x_px, float y_px) const;
  // Clears the edge pixels of region r's corner discs; returns how many were set.
  uint32_t ClearDiscs(const Region& r, EdgeMapView edges) const;

  Region regions_[kMaxHiddenObjects];
  size_t n_regions_ = 0;
  // Disc centres (pixels); plain floats keep the mask trivially copyable (the rescue copies the
  // frame's mask before adding to it).
  float disc_x_[kMaxHiddenDiscs];
  float disc_y_[kMaxHiddenDiscs];
  int n_discs_ = 0;
  uint32_t discs_dropped_ = 0;
};

}  // namespace sh
