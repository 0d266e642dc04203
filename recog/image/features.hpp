// All per-image features of one frame: corners, Canny edges and Hough lines, with one
// configuration and one workspace.
#pragma once

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/canny.hpp"
#include "recog/image/corners.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/image/gaussian.hpp"
#include "recog/image/hough.hpp"
#include "recog/image/image.hpp"

namespace sh {

struct FeatureConfig {
  CornerConfig corners;
  CannyConfig canny;
  HoughConfig hough;
  bool detect_corners = true;
  bool detect_lines = true;  // Canny always runs (verification needs the edge map)

  // Bright objects on a dark background: high contrast, few distracting edges, so a large corner
  // scale (sigma_c 6 px) suppresses spurious corners and a fine Canny scale (1 px) localises.
  static FeatureConfig DarkBackground();
  // Objects on a light, slightly reflective background: lower contrast and more clutter, so
  // sigma_c 2 px and a smoother Canny scale (2 px) with lower thresholds.
  static FeatureConfig LightBackground();
};

// Everything the extraction needs besides the image: about 42 MiB for the largest frame. Keep one
// per concurrently processed image in static storage. `edges` also holds the output edge map.
struct FeatureWorkspace {
  FilterScratch filter;
  EdgeBuffers edges;
  HoughWorkspace hough;
};

struct ImageFeatures {
  Vector<Corner2D, kMaxCorners2d> corners;  // by decreasing strength
  Vector<Line2D, kMaxLines2d> lines;        // in extraction order (decreasing votes)
  EdgeMapView edges;                        // views FeatureWorkspace::edges
  CornerStats corner_stats;
  CannyStats canny_stats;
  HoughStats hough_stats;
};

Status ValidateFeatureConfig(const FeatureConfig& config);

// Runs the detectors on one grey image. On failure the outputs are empty and the Status names
// the problem (empty or oversized image, bad configuration).
Status ExtractFeatures(const ConstGrayView& image, const FeatureConfig& config,
                       FeatureWorkspace& workspace, ImageFeatures& features);

}  // namespace sh
