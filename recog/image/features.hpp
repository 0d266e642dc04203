// All per-image features of one frame: corners, Canny edges and Hough lines, with one
// configuration and one workspace.
#pragma once

#include <algorithm>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/image/canny.hpp"
#include "recog/image/corners.hpp"
#include "recog/image/edge_map.hpp"
#include "recog/image/feature_mask.hpp"
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

  // Thresholds measured from each image instead of fixed ones (the pipeline's default). The
  // image's noise level (noise.hpp) sets them, so that an edge or a corner is kept when it
  // stands out of the noise by the factors below, whatever the camera's gain, the lighting and
  // the table: a grey object on a grey table keeps its edges, a bright one on a dark table is
  // not flooded by noise. canny.low/high_threshold and corners.threshold are then replaced:
  //   Canny low  = max(canny_low_floor, edge_snr x the gradient noise at canny.sigma_px),
  //   Canny high = canny_high_ratio x low,
  //   corners    = strength of a right-angle corner of contrast
  //                max(corner_min_contrast, corner_contrast_snr x noise sigma).
  bool adaptive = false;
  float edge_snr = 5.5f;
  float canny_low_floor = 0.5f;  // grey levels per pixel
  float canny_high_ratio = 2.5f;
  float corner_contrast_snr = 10.0f;
  float corner_min_contrast = 12.0f;  // grey levels

  // Bright objects on a dark background: high contrast, few distracting edges, so a large corner
  // scale (sigma_c 6 px) suppresses spurious corners and a fine Canny scale (1 px) localises.
  static FeatureConfig DarkBackground();
  // Objects on a light, slightly reflective background: lower contrast and more clutter, so
  // sigma_c 2 px and a smoother Canny scale (2 px) with lower thresholds.
  static FeatureConfig LightBackground();
  // Any background: LightBackground's scales with adaptive thresholds (the automatic presets of
  // the stereo and one-camera pipelines, which may change edge_snr or the scales).
  static FeatureConfig Automatic();
};

// Everything the extraction needs besides the image: about 12.25 W H + 588 W bytes for images up
// to W x H (12.7 MiB at 1280 x 800), taken at Init, plus 3.8 MiB of fixed tables. Keep one per
// concurrently processed image. `edges` also holds the output edge map.
struct FeatureWorkspace {
  FilterScratch filter;
  EdgeBuffers edges;
  HoughWorkspace hough;

  // Bytes Init takes for images up to width x height (besides sizeof(FeatureWorkspace)). The
  // Hough transform's pixel lists (collected, subset) share the filter block: ExtractFeatures
  // runs the filters (corners, Canny) before the transform, and nothing reads them after it.
  static size_t BytesFor(int width, int height) {
    return std::max(FilterScratch::BytesFor(width, height),
                    HoughWorkspace::ScratchBytesFor(width, height)) +
           EdgeBuffers::BytesFor(width, height) + HoughWorkspace::OwnBytesFor(width, height);
  }
  // Sizes every buffer for images up to width x height (at start-up: allocates; the same size
  // again keeps them). Refuses sizes beyond kMaxImageWidth x kMaxImageHeight.
  Status Init(int width, int height) {
    SH_RETURN_IF_ERROR(filter.Init(width, height, HoughWorkspace::ScratchBytesFor(width, height)));
    SH_RETURN_IF_ERROR(edges.Init(width, height));
    return hough.Init(width, height, filter.block().data(), filter.block().bytes());
  }
};

// What the detectors used on one image: the noise measured, and the thresholds (with
// `adaptive`: chosen from it).
struct DetectionChoice {
  bool adaptive = false;
  float noise_sigma = 0.0f;  // measured sensor noise, grey levels
  float canny_low = 0.0f, canny_high = 0.0f;
  float corner_threshold = 0.0f;
  // Blocks of kTextureBlockPx x kTextureBlockPx pixels whose texture raised the Canny thresholds
  // (CannyConfig::texture_factor), of texture_blocks.
  uint32_t textured_blocks = 0, texture_blocks = 0;
};

struct ImageFeatures {
  Vector<Corner2D, kMaxCorners2d> corners;  // by decreasing strength
  Vector<Line2D, kMaxLines2d> lines;        // in extraction order (decreasing votes)
  EdgeMapView edges;                        // views FeatureWorkspace::edges
  CornerStats corner_stats;
  CannyStats canny_stats;
  HoughStats hough_stats;
  DetectionChoice chosen;
  // Hidden by the mask (ExtractFeatures' `mask`): corners dropped, edge pixels cleared.
  uint32_t masked_corners = 0, masked_edge_pixels = 0;
};

Status ValidateFeatureConfig(const FeatureConfig& config);

// The detector settings for one image: `config` itself, or with `adaptive` the thresholds
// measured from the image. `chosen` records them.
Status ChooseDetection(const ConstGrayView& image, const FeatureConfig& config,
                       FeatureConfig* effective, DetectionChoice* chosen);

// Runs the detectors on one grey image. On failure the outputs are empty and the Status names
// the problem (empty or oversized image, bad configuration). With a `mask`, the corners it
// hides are dropped and its edge pixels cleared before the line detector runs, so the lines and
// the returned edge map have none of them either.
Status ExtractFeatures(const ConstGrayView& image, const FeatureConfig& config,
                       FeatureWorkspace& workspace, ImageFeatures& features,
                       const FeatureMask* mask = nullptr);

}  // namespace sh
