#include "recog/image/features.hpp"

#include <algorithm>

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

namespace {

// Corners and Canny at the same scale both start from the image smoothed at
// DifferenceSmoothingSigma(sigma): smooth once, and per row take the corner response and the
// gradient for the edge tracer while the three smoothed rows are in cache. The results are those
// of DetectCorners and DetectEdges (the same arithmetic on the same rows). The configuration has
// been validated.
void SharedScaleCornersAndEdges(const ConstGrayView& image, const FeatureConfig& config,
                                FeatureWorkspace& workspace, ImageFeatures& features) {
  const int w = image.width, h = image.height;
  FilterScratch& scratch = workspace.filter;
  GaussianKernel g0;
  (void)MakeGaussianKernel(DifferenceSmoothingSigma(config.canny.sigma_px), 0, g0);  // valid
  ImageView<float> rows = scratch.planes[0].view(w, h);
  ImageView<float> smooth = scratch.planes[1].view(w, h);
  ImageView<float> resp = scratch.planes[3].view(w, h);
  FilterRows(image, &g0, rows, nullptr, {}, nullptr, {});
  const float scale = CornerResponseScale(config.corners.sigma_px);
  float max_strength = 0.0f;
  EdgeTracer tracer(config.canny, workspace.edges, w, h);
  float gx[kMaxImageWidth], gy[kMaxImageWidth];
  auto consume_row = [&](int y) {
    const float* up = smooth.row(std::max(0, y - 1));
    const float* mid = smooth.row(y);
    const float* down = smooth.row(std::min(h - 1, y + 1));
    max_strength = std::max(max_strength, CornerResponseRow(up, mid, down, w, scale, resp.row(y)));
    GradientRow(up, mid, down, w, gx, gy);
    tracer.AddRow(gx, gy);
  };
  for (int y = 0; y < h; ++y) {
    FilterColumnRow(rows, g0, y, smooth.row(y));
    if (y >= 1) consume_row(y - 1);
  }
  consume_row(h - 1);
  tracer.Finish(features.edges, &features.canny_stats);
  CornersFromResponse(image, config.corners, resp, max_strength, features.corners,
                      &features.corner_stats);
}

}  // namespace

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
  if (config.detect_corners && CornersUseSmoothedImage(config.corners) &&
      config.corners.sigma_px == config.canny.sigma_px) {
    SharedScaleCornersAndEdges(image, config, workspace, features);
  } else {
    if (config.detect_corners) {
      SH_RETURN_IF_ERROR(DetectCorners(image, config.corners, workspace.filter, features.corners,
                                       &features.corner_stats));
    }
    SH_RETURN_IF_ERROR(DetectEdges(image, config.canny, workspace.filter, workspace.edges,
                                   features.edges, &features.canny_stats));
  }
  if (config.detect_lines) {
    const ConstEdgeMapView edges{features.edges.edge, features.edges.orientation};
    SH_RETURN_IF_ERROR(
        DetectLines(edges, config.hough, workspace.hough, features.lines, &features.hough_stats));
  }
  return Status::Ok();
}

}  // namespace sh
