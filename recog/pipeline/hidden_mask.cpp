#include "recog/pipeline/hidden_mask.hpp"

#include <algorithm>
#include <cmath>

#include "recog/geometry/convex_hull.hpp"

namespace sh {

bool HiddenMask::Add(const ViewCamera& view, const PosedModel& object, float margin_px,
                     float corner_radius_px) {
  if (n_regions_ == kMaxHiddenObjects || object.model == nullptr) return false;
  const Model& model = *object.model;
  const RigidTransform cam_T_model = view.cam_T_left * object.cam_T_model;
  // Model points to project: samples along the edges (endpoints included), or the corners when
  // the model has too many edges for samples along each.
  Eigen::Vector2f points[kMaxOutlinePoints];
  int n = 0;
  const auto project = [&](const Eigen::Vector3f& x_model_mm) {
    Eigen::Vector2d pixel;
    if (!ProjectToPixel(view.intrinsics, (cam_T_model * x_model_mm).cast<double>(), &pixel)) {
      return false;
    }
    points[n++] = pixel.cast<float>();
    return true;
  };
  const int per_edge = model.n_edges > 0 ? std::min(9, kMaxOutlinePoints / model.n_edges) : 0;
  if (per_edge >= 2) {
    for (int e = 0; e < model.n_edges; ++e) {
      const Eigen::Vector3f a = model.corner(model.edges[e].a), b = model.corner(model.edges[e].b);
      for (int k = 0; k < per_edge; ++k) {
        const float t = static_cast<float>(k) / static_cast<float>(per_edge - 1);
        if (!project(a + t * (b - a))) return false;
      }
    }
  } else {
    for (int i = 0; i < model.n_corners && n < kMaxOutlinePoints; ++i) {
      if (!project(model.corner(i))) return false;
    }
  }
  Eigen::Vector2f hull[kMaxOutlinePoints + 1];
  const int h = ConvexHull2D(points, n, hull);
  if (h < 3) return false;

  Region& r = regions_[n_regions_];
  r.n = 0;
  float x_min = hull[0].x(), x_max = hull[0].x(), y_min = hull[0].y(), y_max = hull[0].y();
  for (int i = 0; i < h; ++i) {
    const Eigen::Vector2f& p = hull[i];
    const Eigen::Vector2f& q = hull[(i + 1) % h];
    x_min = std::min(x_min, p.x());
    x_max = std::max(x_max, p.x());
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
    // Left turns: the interior is left of p -> q; the outward normal is (dy, -dx).
    const float nx = q.y() - p.y(), ny = -(q.x() - p.x());
    const float len = std::sqrt(nx * nx + ny * ny);
    if (!(len > 1e-6f)) continue;
    r.a[r.n] = nx / len;
    r.b[r.n] = ny / len;
    r.c[r.n] = r.a[r.n] * p.x() + r.b[r.n] * p.y() + margin_px;
    ++r.n;
  }
  const float box[4][3] = {{1, 0, x_max + margin_px},
                           {-1, 0, -(x_min - margin_px)},
                           {0, 1, y_max + margin_px},
                           {0, -1, -(y_min - margin_px)}};
  for (const auto& half : box) {
    r.a[r.n] = half[0];
    r.b[r.n] = half[1];
    r.c[r.n] = half[2];
    ++r.n;
  }
  r.y_min = y_min - margin_px;
  r.y_max = y_max + margin_px;
  r.first_disc = n_discs_;
  r.n_discs = 0;
  r.disc_radius_px = std::max(0.0f, corner_radius_px);
  if (r.disc_radius_px > 0.0f) {
    for (int i = 0; i < model.n_corners; ++i) {
      Eigen::Vector2d pixel;
      if (!ProjectToPixel(view.intrinsics, (cam_T_model * model.corner(i)).cast<double>(),
                          &pixel)) {
        continue;  // in front of the camera: checked with the outline above
      }
      if (n_discs_ == kMaxHiddenDiscs) {
        ++discs_dropped_;
        continue;
      }
      disc_x_[n_discs_] = static_cast<float>(pixel.x());
      disc_y_[n_discs_] = static_cast<float>(pixel.y());
      ++n_discs_;
      ++r.n_discs;
      r.y_min = std::min(r.y_min, static_cast<float>(pixel.y()) - r.disc_radius_px);
      r.y_max = std::max(r.y_max, static_cast<float>(pixel.y()) + r.disc_radius_px);
    }
  }
  ++n_regions_;
  return true;
}

bool HiddenMask::InDisc(const Region& r, float x_px, float y_px) const {
  const float r2 = r.disc_radius_px * r.disc_radius_px;
  for (int k = r.first_disc; k < r.first_disc + r.n_discs; ++k) {
    const float dx = x_px - disc_x_[k], dy = y_px - disc_y_[k];
    if (dx * dx + dy * dy <= r2) return true;
  }
  return false;
}

bool HiddenMask::Hides(float x_px, float y_px) const {
  for (size_t i = 0; i < n_regions_; ++i) {
    const Region& r = regions_[i];
    if (y_px < r.y_min || y_px > r.y_max) continue;
    bool inside = true;
    for (int k = 0; k < r.n && inside; ++k) inside = r.a[k] * x_px + r.b[k] * y_px <= r.c[k];
    if (inside || InDisc(r, x_px, y_px)) return true;
  }
  return false;
}

void HiddenMask::RowSpan(size_t i, int y, int width, int* x_begin, int* x_end) const {
  *x_begin = 0;
  *x_end = 0;
  if (i >= n_regions_) return;
  const Region& r = regions_[i];
  const float yf = static_cast<float>(y);
  if (yf < r.y_min || yf > r.y_max) return;
  float lo = 0.0f, hi = static_cast<float>(width - 1);
  for (int k = 0; k < r.n; ++k) {
    const float rhs = r.c[k] - r.b[k] * yf;  // a x <= rhs on this row
    if (r.a[k] > 1e-6f) {
      hi = std::min(hi, rhs / r.a[k]);
    } else if (r.a[k] < -1e-6f) {
      lo = std::max(lo, rhs / r.a[k]);
    } else if (rhs < 0.0f) {
      return;  // a horizontal edge with the row outside it
    }
  }
  if (!(lo <= hi)) return;
  *x_begin = static_cast<int>(std::ceil(lo));
  *x_end = static_cast<int>(std::floor(hi)) + 1;
}

uint32_t HiddenMask::ClearEdges(EdgeMapView edges) const {
  uint32_t cleared = 0;
  const ImageView<uint8_t>& e = edges.edge;
  for (size_t i = 0; i < n_regions_; ++i) {
    const Region& r = regions_[i];
    const int y0 = std::max(0, static_cast<int>(std::ceil(r.y_min)));
    const int y1 = std::min(e.height - 1, static_cast<int>(std::floor(r.y_max)));
    for (int y = y0; y <= y1; ++y) {
      int x0 = 0, x1 = 0;
      RowSpan(i, y, e.width, &x0, &x1);
      uint8_t* row = e.data + static_cast<ptrdiff_t>(y) * e.stride;
      for (int x = x0; x < x1; ++x) {
        cleared += row[x] != 0;
        row[x] = 0;
      }
    }
    cleared += ClearDiscs(r, edges);
  }
  return cleared;
}

uint32_t HiddenMask::ClearDiscs(const Region& r, EdgeMapView edges) const {
  uint32_t cleared = 0;
  const ImageView<uint8_t>& e = edges.edge;
  const float rad = r.disc_radius_px;
  for (int k = r.first_disc; k < r.first_disc + r.n_discs; ++k) {
    const float cx = disc_x_[k], cy = disc_y_[k];
    const int y0 = std::max(0, static_cast<int>(std::ceil(cy - rad)));
    const int y1 = std::min(e.height - 1, static_cast<int>(std::floor(cy + rad)));
    const int x0 = std::max(0, static_cast<int>(std::ceil(cx - rad)));
    const int x1 = std::min(e.width - 1, static_cast<int>(std::floor(cx + rad)));
    for (int y = y0; y <= y1; ++y) {
      uint8_t* row = e.data + static_cast<ptrdiff_t>(y) * e.stride;
      for (int x = x0; x <= x1; ++x) {
        const float dx = static_cast<float>(x) - cx, dy = static_cast<float>(y) - cy;
        if (dx * dx + dy * dy > rad * rad) continue;
        cleared += row[x] != 0;
        row[x] = 0;
      }
    }
  }
  return cleared;
}

}  // namespace sh
