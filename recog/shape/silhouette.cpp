#include "recog/shape/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

constexpr float kMinDepthMm = 1.0f;

// Fills the pixel centres inside polygon `poly` (even-odd rule) into the mask.
void FillPolygon(const float (*corners)[2], const uint8_t* vertices, int n, SilhouetteMask* m) {
  float ymin = corners[vertices[0]][1], ymax = ymin;
  for (int k = 1; k < n; ++k) {
    ymin = std::min(ymin, corners[vertices[k]][1]);
    ymax = std::max(ymax, corners[vertices[k]][1]);
  }
  const int row_begin = std::max(m->y0, static_cast<int>(std::ceil(ymin)));
  const int row_end = std::min(m->y0 + m->height - 1, static_cast<int>(std::floor(ymax)));
  float xs[kMaxFaceVertices];
  for (int y = row_begin; y <= row_end; ++y) {
    const float py = static_cast<float>(y);
    int n_x = 0;
    for (int k = 0, j = n - 1; k < n; j = k++) {
      const float* a = corners[vertices[j]];
      const float* b = corners[vertices[k]];
      // Half-open in y so a vertex on the scanline counts once.
      if ((a[1] <= py) != (b[1] <= py)) {
        xs[n_x++] = a[0] + (py - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
      }
    }
    std::sort(xs, xs + n_x);
    uint8_t* row = m->mask + static_cast<size_t>(y - m->y0) * m->width;
    for (int i = 0; i + 1 < n_x; i += 2) {
      // Pixel centres x with xs[i] <= x < xs[i + 1].
      const int xa = std::max(m->x0, static_cast<int>(std::ceil(xs[i])));
      const int xb = std::min(m->x0 + m->width, static_cast<int>(std::ceil(xs[i + 1])));
      if (xb > xa) std::memset(row + (xa - m->x0), 255, static_cast<size_t>(xb - xa));
    }
  }
}

}  // namespace

Status RasterizeSilhouette(const ViewCamera& camera, const PosedModel& object,
                           SilhouetteScratch& scratch, SilhouetteMask* out) {
  if (object.model == nullptr || out == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "silhouette: null model or output");
  }
  const Model& model = *object.model;
  SH_RETURN_IF_ERROR(CheckModel(model));
  const CameraIntrinsics& cam = camera.intrinsics;
  *out = SilhouetteMask{};
  out->mask = scratch.mask;
  const RigidTransform cam_T_model = camera.cam_T_left * object.cam_T_model;
  const double max_r2 = MaxImageRadius2(cam);
  float xmin = 1e30f, xmax = -1e30f, ymin = 1e30f, ymax = -1e30f;
  for (int i = 0; i < model.n_corners; ++i) {
    const Eigen::Vector3f x = cam_T_model * model.corner(i);
    if (!(x.z() >= kMinDepthMm)) {
      return Status::Error(StatusCode::kOutOfRange,
                           "silhouette: model '%.31s' reaches depth %.1f mm, behind the camera",
                           model.name, static_cast<double>(x.z()));
    }
    Eigen::Vector2f px;
    if (!ProjectInView(cam, max_r2, x, &px)) {
      // Far outside the image, where the distortion polynomial may fold back: the pinhole
      // projection keeps the corner outside, which is all the clipping needs.
      px = {static_cast<float>(cam.fx * x.x() / x.z() + cam.cx),
            static_cast<float>(cam.fy * x.y() / x.z() + cam.cy)};
    }
    scratch.corners_px[i][0] = px.x();
    scratch.corners_px[i][1] = px.y();
    xmin = std::min(xmin, px.x());
    xmax = std::max(xmax, px.x());
    ymin = std::min(ymin, px.y());
    ymax = std::max(ymax, px.y());
  }
  const int bx0 = static_cast<int>(std::ceil(xmin)), bx1 = static_cast<int>(std::floor(xmax));
  const int by0 = static_cast<int>(std::ceil(ymin)), by1 = static_cast<int>(std::floor(ymax));
  out->x0 = std::max(0, bx0);
  out->y0 = std::max(0, by0);
  const int x1 = std::min(cam.width - 1, bx1), y1 = std::min(cam.height - 1, by1);
  out->clipped = bx0 < 0 || by0 < 0 || bx1 > cam.width - 1 || by1 > cam.height - 1;
  if (x1 < out->x0 || y1 < out->y0) {
    out->width = out->height = 0;
    return Status::Ok();
  }
  out->width = x1 - out->x0 + 1;
  out->height = y1 - out->y0 + 1;
  std::memset(scratch.mask, 0, static_cast<size_t>(out->width) * out->height);

  // Front faces only: every ray that meets a closed solid enters it through one.
  const Eigen::Vector3f centre_model = cam_T_model.Inverse().t_mm;
  for (int f = 0; f < model.n_faces; ++f) {
    const ModelFace& face = model.faces[f];
    if (model.face_normal(f).dot(centre_model) - face.offset_mm <= 0.0f) continue;
    FillPolygon(scratch.corners_px, face.vertices, face.n_vertices, out);
  }
  // Sums of pixel coordinates in integers (a loop the compiler vectorises): exact, as the
  // doubles they become are for any image.
  uint64_t sx = 0, sy = 0;
  uint32_t area = 0;
  for (int y = 0; y < out->height; ++y) {
    const uint8_t* row = scratch.mask + static_cast<size_t>(y) * out->width;
    uint32_t n = 0, row_sx = 0;
    for (int x = 0; x < out->width; ++x) {
      // All ones inside, zero outside: a mask rather than a product (no 32-bit lane multiply
      // in the baseline x86-64 vector instructions).
      const uint32_t in = row[x] != 0 ? ~0u : 0u;
      n += in & 1u;
      row_sx += in & static_cast<uint32_t>(x);
    }
    area += n;
    sx += row_sx;
    sy += static_cast<uint64_t>(y) * n;
  }
  out->area_px = area;
  if (area > 0) {
    out->cx = static_cast<float>(out->x0 + static_cast<double>(sx) / area);
    out->cy = static_cast<float>(out->y0 + static_cast<double>(sy) / area);
  }
  return Status::Ok();
}

}  // namespace sh
