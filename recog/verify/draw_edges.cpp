#include "recog/verify/draw_edges.hpp"

#include <cmath>
#include <cstdlib>

namespace sh {
namespace {

// Sample step and depth limit used when drawing a posed model directly.
constexpr float kDrawStepPx = 1.0f;
constexpr float kDrawMinDepthMm = 1.0f;
// A polyline piece longer than this cannot come from consecutive samples inside the image's
// field: it is a projection artefact far outside and is not drawn.
constexpr int kMaxPieceLengthPx = 64;

template <typename T>
void DrawLine(ImageView<T> image, int x0, int y0, int x1, int y1, T value) {
  const int dx = std::abs(x1 - x0), sx = x0 < x1 ? 1 : -1;
  const int dy = -std::abs(y1 - y0), sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (;;) {
    if (image.contains(x0, y0)) image.at(x0, y0) = value;
    if (x0 == x1 && y0 == y1) return;
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x0 += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y0 += sy;
    }
  }
}

template <typename T>
Status Draw(const ViewCamera& camera, const VisibleEdgeSet& visible, ImageView<T> image, T value) {
  const CameraIntrinsics& cam = camera.intrinsics;
  if (image.empty() || image.width != cam.width || image.height != cam.height ||
      image.stride < image.width) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "draw edges: image %dx%d does not match camera %dx%d", image.width,
                         image.height, cam.width, cam.height);
  }
  const double max_r2 = MaxImageRadius2(cam);
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    for (int r = 0; r < ve.n_runs; ++r) {
      // Polyline through the run's sample boundaries: fractions first/n .. end/n.
      bool have_previous = false;
      int x_prev = 0, y_prev = 0;
      for (int i = ve.runs[r].first; i <= ve.runs[r].end; ++i) {
        const float s = static_cast<float>(i) / ve.n_samples;
        Eigen::Vector2f p;
        if (!ProjectInView(cam, max_r2, PointAtImageFraction(ve, s), &p)) {
          have_previous = false;
          continue;
        }
        const int x = static_cast<int>(std::floor(p.x() + 0.5f));
        const int y = static_cast<int>(std::floor(p.y() + 0.5f));
        if (have_previous && std::abs(x - x_prev) <= kMaxPieceLengthPx &&
            std::abs(y - y_prev) <= kMaxPieceLengthPx) {
          DrawLine(image, x_prev, y_prev, x, y, value);
        }
        have_previous = true;
        x_prev = x;
        y_prev = y;
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status DrawVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible, GrayView image,
                        uint8_t value) {
  return Draw(camera, visible, image, value);
}

Status DrawVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible,
                        ImageView<Rgb8> image, Rgb8 colour) {
  return Draw(camera, visible, image, colour);
}

Status DrawPosedModel(const ViewCamera& camera, const PosedModel& object,
                      const PosedModel* occluders, size_t n_occluders, GrayView image,
                      uint8_t value) {
  VisibleEdgeSet visible;
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(camera, object, occluders, n_occluders, kDrawStepPx,
                                         kDrawMinDepthMm, &visible));
  return Draw(camera, visible, image, value);
}

Status DrawPosedModel(const ViewCamera& camera, const PosedModel& object,
                      const PosedModel* occluders, size_t n_occluders, ImageView<Rgb8> image,
                      Rgb8 colour) {
  VisibleEdgeSet visible;
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(camera, object, occluders, n_occluders, kDrawStepPx,
                                         kDrawMinDepthMm, &visible));
  return Draw(camera, visible, image, colour);
}

}  // namespace sh
