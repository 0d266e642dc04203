#include "recog/image/features.hpp"

#include <cmath>

#include "recog/image/noise.hpp"

namespace sh {

namespace {

// Standard deviation of the Canny gradient component (G1 along one axis, G0 along the other)
// for white noise of unit variance: the root of the sums of the squared taps.
float GradientNoiseGain(float sigma_px) {
  GaussianKernel g0, g1;
  if (!MakeGaussianKernel(sigma_px, 0, g0).ok() || !MakeGaussianKernel(sigma_px, 1, g1).ok()) {
    return 0.0f;
  }
  double s0 = 0.0, s1 = 0.0;
  for (int k = 0; k <= g0.radius; ++k) s0 += (k == 0 ? 1.0 : 2.0) * g0.taps[k] * g0.taps[k];
  for (int k = 0; k <= g1.radius; ++k) s1 += (k == 0 ? 1.0 : 2.0) * g1.taps[k] * g1.taps[k];
  return static_cast<float>(std::sqrt(s0 * s1));
}

}  // namespace

FeatureConfig FeatureConfig::DarkBackground() {
  FeatureConfig c;
  c.corners.sigma_px = 6.0f;
  // About a right-angle corner of contrast 55; obtuse corners respond less.
  c.corners.threshold = 0.01f;
  c.corners.nms_radius_px = 6;
  c.canny.sigma_px = 1.0f;
  c.canny.low_threshold = 4.0f;
  c.canny.high_threshold = 10.0f;
  return c;
}

FeatureConfig FeatureConfig::LightBackground() {
  FeatureConfig c;
  c.corners.sigma_px = 2.0f;
  // Objects differ less from a light background: about a right-angle corner of contrast 40.
  c.corners.threshold = 0.004f;
  c.corners.nms_radius_px = 3;
  c.canny.sigma_px = 2.0f;
  // The peak gradient of a step halves when sigma doubles.
  c.canny.low_threshold = 2.0f;
  c.canny.high_threshold = 5.0f;
  return c;
}

FeatureConfig FeatureConfig::Automatic() {
  FeatureConfig c = LightBackground();
  c.adaptive = true;
  // 1.5 px: the low-contrast edges of dark objects on their shadows survive, and with
  // noise-relative thresholds the finer scale does not admit noise.
  c.canny.sigma_px = 1.5f;
  // Corners: the detector integrates over sigma_c (2 px), so a corner stands out of the pixel
  // noise at a far lower contrast than ten noise sigmas. Four sigmas, with 20 grey levels as the
  // floor that the thresholds of clean images (noise about 2) came to before: a camera at gain
  // keeps its corners (and its 3-D support) where ten sigmas dropped two thirds of them.
  c.corner_contrast_snr = 4.0f;
  c.corner_min_contrast = 20.0f;
  // Edges: 3.5 gradient-noise sigmas keep the defocused, low-contrast outlines of a factory
  // floor (grey parts on grey tables, sensor noise 3-6 grey levels) connected, and those a
  // camera at gain blurs into its noise. The noise edges this admits form no object in the
  // stereo pipeline, whose verifier wants an outline confirmed in both images; the texture
  // factor below keeps a grained table's ripples out. Over twenty polyhedral sets (shared and
  // own, clean and factory floor) 3.5 found 13 objects more than 4.5 with 2 false alarms fewer
  // and lost none on any set; 3.0 found as many, and 2.5 added false alarms on clean sets.
  c.edge_snr = 3.5f;
  // A grained or mottled table is no noise: at those thresholds its every ripple is an edge,
  // and its hundreds of lines cost the search its time. Over such texture an edge must stand
  // three times above the block's lower quartile of gradient (CannyConfig::texture_factor).
  c.canny.texture_factor = 3.0f;
  return c;
}

Status ValidateFeatureConfig(const FeatureConfig& config) {
  if (config.detect_corners) SH_RETURN_IF_ERROR(ValidateCornerConfig(config.corners));
  SH_RETURN_IF_ERROR(ValidateCannyConfig(config.canny));
  if (config.detect_lines) SH_RETURN_IF_ERROR(ValidateHoughConfig(config.hough));
  return Status::Ok();
}

Status ChooseDetection(const ConstGrayView& image, const FeatureConfig& config,
                       FeatureConfig* effective, DetectionChoice* chosen) {
  *effective = config;
  *chosen = DetectionChoice{};
  // Measured with a preset too: the verifier's faint-edge test needs it (VerifyConfig).
  const NoiseEstimate noise = EstimateNoise(image);
  chosen->noise_sigma = noise.sigma;
  if (config.adaptive) {
    if (!(config.edge_snr > 0 && config.canny_low_floor > 0 && config.canny_high_ratio >= 1 &&
          config.corner_contrast_snr > 0 && config.corner_min_contrast > 0 &&
          config.corner_min_contrast < 256)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "adaptive detection needs positive factors, a high/low ratio >= 1 and "
                           "a minimum corner contrast in (0, 256)");
    }
    const float gradient_noise = noise.sigma * GradientNoiseGain(config.canny.sigma_px);
    effective->canny.low_threshold =
        std::fmax(config.canny_low_floor, config.edge_snr * gradient_noise);
    effective->canny.high_threshold = config.canny_high_ratio * effective->canny.low_threshold;
    // Corner strength grows with the cube of the contrast; 1.0 is a right angle of contrast 255.
    const float contrast = std::fmin(
        255.0f, std::fmax(config.corner_min_contrast, config.corner_contrast_snr * noise.sigma));
    const float c = contrast / 255.0f;
    effective->corners.threshold = c * c * c;
  }
  chosen->adaptive = config.adaptive;
  chosen->canny_low = effective->canny.low_threshold;
  chosen->canny_high = effective->canny.high_threshold;
  chosen->corner_threshold = effective->corners.threshold;
  return Status::Ok();
}

Status ExtractFeatures(const ConstGrayView& image, const FeatureConfig& requested,
                       FeatureWorkspace& workspace, ImageFeatures& features,
                       const FeatureMask* mask) {
  features.corners.clear();
  features.lines.clear();
  features.edges = EdgeMapView{};
  features.corner_stats = CornerStats{};
  features.canny_stats = CannyStats{};
  features.hough_stats = HoughStats{};
  features.chosen = DetectionChoice{};
  features.masked_corners = 0;
  features.masked_edge_pixels = 0;
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "ExtractFeatures"));
  SH_RETURN_IF_ERROR(CheckFitsWorkspace(image.width, image.height, workspace.filter.block(),
                                        "ExtractFeatures (workspace)"));
  FeatureConfig config;
  SH_RETURN_IF_ERROR(ChooseDetection(image, requested, &config, &features.chosen));
  SH_RETURN_IF_ERROR(ValidateFeatureConfig(config));
  if (config.detect_corners) {
    SH_RETURN_IF_ERROR(DetectCorners(image, config.corners, workspace.filter, features.corners,
                                     &features.corner_stats));
  }
  SH_RETURN_IF_ERROR(DetectEdges(image, config.canny, workspace.filter, workspace.edges,
                                 features.edges, &features.canny_stats));
  // Both 0 when the texture test is off.
  features.chosen.textured_blocks = static_cast<uint32_t>(features.canny_stats.textured_blocks);
  features.chosen.texture_blocks = static_cast<uint32_t>(features.canny_stats.texture_blocks);
  if (mask != nullptr) {
    // In place, keeping the order of strength.
    size_t kept = 0;
    for (size_t i = 0; i < features.corners.size(); ++i) {
      const Corner2D& c = features.corners[i];
      if (mask->Hides(c.x_px, c.y_px)) continue;
      features.corners[kept++] = c;
    }
    features.masked_corners = static_cast<uint32_t>(features.corners.size() - kept);
    features.corners.resize(kept);
    features.masked_edge_pixels = mask->ClearEdges(features.edges);
  }
  if (config.detect_lines) {
    const ConstEdgeMapView edges{features.edges.edge, features.edges.orientation};
    SH_RETURN_IF_ERROR(
        DetectLines(edges, config.hough, workspace.hough, features.lines, &features.hough_stats));
  }
  return Status::Ok();
}

}  // namespace sh
