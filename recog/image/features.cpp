#include "recog/image/features.hpp"

namespace sh {

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

Status ValidateFeatureConfig(const FeatureConfig& config) {
  if (config.detect_corners) SH_RETURN_IF_ERROR(ValidateCornerConfig(config.corners));
  SH_RETURN_IF_ERROR(ValidateCannyConfig(config.canny));
  if (config.detect_lines) SH_RETURN_IF_ERROR(ValidateHoughConfig(config.hough));
  return Status::Ok();
}

Status ExtractFeatures(const ConstGrayView& image, const FeatureConfig& config,
                       FeatureWorkspace& workspace, ImageFeatures& features) {
  features.corners.clear();
  features.lines.clear();
  features.edges = EdgeMapView{};
  features.corner_stats = CornerStats{};
  features.canny_stats = CannyStats{};
  features.hough_stats = HoughStats{};
  SH_RETURN_IF_ERROR(ValidateGrayImage(image, "ExtractFeatures"));
  SH_RETURN_IF_ERROR(ValidateFeatureConfig(config));
  if (config.detect_corners) {
    SH_RETURN_IF_ERROR(DetectCorners(image, config.corners, workspace.filter, features.corners,
                                     &features.corner_stats));
  }
  SH_RETURN_IF_ERROR(DetectEdges(image, config.canny, workspace.filter, workspace.edges,
                                 features.edges, &features.canny_stats));
  if (config.detect_lines) {
    const ConstEdgeMapView edges{features.edges.edge, features.edges.orientation};
    SH_RETURN_IF_ERROR(
        DetectLines(edges, config.hough, workspace.hough, features.lines, &features.hough_stats));
  }
  return Status::Ok();
}

}  // namespace sh
