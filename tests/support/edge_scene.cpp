#include "tests/support/edge_scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace sh::testing {

Eigen::Matrix3f AxisAngleDeg(const Eigen::Vector3f& axis, float angle_deg) {
  return Eigen::AngleAxisf(angle_deg * static_cast<float>(M_PI / 180.0), axis.normalized())
      .toRotationMatrix();
}

namespace {

// Winding angle of the polygon around h, measured about the face normal: +-2 pi inside, 0
// outside.
bool InsideByWinding(const Model& m, const ModelFace& face, const Eigen::Vector3d& h) {
  // Bounding-box rejection first: the winding sum costs an atan2 per vertex.
  Eigen::Vector3d lo = m.corner(face.vertices[0]).cast<double>(), hi = lo;
  for (int k = 1; k < face.n_vertices; ++k) {
    lo = lo.cwiseMin(m.corner(face.vertices[k]).cast<double>());
    hi = hi.cwiseMax(m.corner(face.vertices[k]).cast<double>());
  }
  if ((h.array() < lo.array() - 1e-6).any() || (h.array() > hi.array() + 1e-6).any()) {
    return false;
  }
  const Eigen::Vector3d n(face.normal[0], face.normal[1], face.normal[2]);
  double total = 0;
  for (int k = 0; k < face.n_vertices; ++k) {
    const Eigen::Vector3d a = m.corner(face.vertices[k]).cast<double>() - h;
    const Eigen::Vector3d b = m.corner(face.vertices[(k + 1) % face.n_vertices]).cast<double>() - h;
    total += std::atan2(n.dot(a.cross(b)), a.dot(b));
  }
  return std::fabs(total) > M_PI;
}

// Nearest intersection (ray parameter, distance along the unit or non-unit direction d) of the
// ray c + t d with the model, all in the model frame; face index in *face.
double NearestHit(const Model& m, const Eigen::Vector3d& c, const Eigen::Vector3d& d, int* face) {
  double best = std::numeric_limits<double>::infinity();
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& mf = m.faces[f];
    const Eigen::Vector3d n(mf.normal[0], mf.normal[1], mf.normal[2]);
    const double nd = n.dot(d);
    if (std::fabs(nd) < 1e-12) continue;
    const double t = (mf.offset_mm - n.dot(c)) / nd;
    if (!(t > 0) || t >= best) continue;
    if (InsideByWinding(m, mf, c + t * d)) {
      best = t;
      *face = f;
    }
  }
  return best;
}

// Region id (RenderRegions) seen through a pixel position.
int RegionSeen(const CameraIntrinsics& cam, const std::vector<PosedModel>& objects,
               const std::vector<RigidTransform>& model_T_cam, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d ray = PixelRay(cam, pixel);
  double best = std::numeric_limits<double>::infinity();
  int region = 0;
  for (size_t k = 0; k < objects.size(); ++k) {
    const Eigen::Vector3d c = model_T_cam[k].t_mm.cast<double>();
    const Eigen::Vector3d d = model_T_cam[k].R.cast<double>() * ray;
    int face = -1;
    const double t = NearestHit(*objects[k].model, c, d, &face);
    if (t < best) {
      best = t;
      region = static_cast<int>(k) * 64 + face + 1;
    }
  }
  return region;
}

std::vector<RigidTransform> ModelsFromCamera(const ViewCamera& view,
                                             const std::vector<PosedModel>& objects) {
  std::vector<RigidTransform> model_T_cam;
  model_T_cam.reserve(objects.size());
  for (const PosedModel& o : objects) {
    model_T_cam.push_back((view.cam_T_left * o.cam_T_model).Inverse());
  }
  return model_T_cam;
}

}  // namespace

std::vector<int> RenderRegions(const ViewCamera& view, const std::vector<PosedModel>& objects) {
  const CameraIntrinsics& cam = view.intrinsics;
  const std::vector<RigidTransform> model_T_cam = ModelsFromCamera(view, objects);
  std::vector<int> regions(static_cast<size_t>(cam.width) * cam.height, 0);
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      regions[static_cast<size_t>(y) * cam.width + x] =
          RegionSeen(cam, objects, model_T_cam, Eigen::Vector2d(x, y));
    }
  }
  return regions;
}

EdgeMapBuffer RenderEdgeMap(const ViewCamera& view, const std::vector<PosedModel>& objects) {
  const CameraIntrinsics& cam = view.intrinsics;
  const int w = cam.width, h = cam.height;
  EdgeMapBuffer out(w, h);
  // Bounding box of the projected corners, with a margin for distortion-bent edges.
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  for (const PosedModel& o : objects) {
    const RigidTransform cam_T_model = view.cam_T_left * o.cam_T_model;
    for (int i = 0; i < o.model->n_corners; ++i) {
      Eigen::Vector2d p;
      if (!ProjectToPixel(cam, (cam_T_model * o.model->corner(i)).cast<double>(), &p)) continue;
      x0 = std::min(x0, static_cast<int>(std::floor(p.x())) - 6);
      y0 = std::min(y0, static_cast<int>(std::floor(p.y())) - 6);
      x1 = std::max(x1, static_cast<int>(std::ceil(p.x())) + 6);
      y1 = std::max(y1, static_cast<int>(std::ceil(p.y())) + 6);
    }
  }
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, w - 1);
  y1 = std::min(y1, h - 1);
  if (x0 > x1 || y0 > y1) return out;

  // Region ids on a 3 x 3 sub-pixel grid over the box: the centre sub-sample decides where the
  // edge pixels are, the coverage of the sub-samples gives anti-aliased boundaries from which
  // the orientation is measured (aliased binary boundaries bias it by 10 degrees and more).
  const int bw = x1 - x0 + 1, bh = y1 - y0 + 1;
  std::vector<int> sub(static_cast<size_t>(9) * bw * bh, 0);
  const std::vector<RigidTransform> model_T_cam = ModelsFromCamera(view, objects);
  for (int sy = 0; sy < 3 * bh; ++sy) {
    for (int sx = 0; sx < 3 * bw; ++sx) {
      const Eigen::Vector2d pixel(x0 + (sx - 1) / 3.0, y0 + (sy - 1) / 3.0);  // centre at sx%3 == 1
      sub[static_cast<size_t>(sy) * 3 * bw + sx] = RegionSeen(cam, objects, model_T_cam, pixel);
    }
  }
  auto sub_region = [&](int x, int y, int i, int j) {    // sub-sample (i, j) of pixel (x, y)
    if (x < x0 || y < y0 || x > x1 || y > y1) return 0;  // outside the box: background
    return sub[static_cast<size_t>(3 * (y - y0) + j) * 3 * bw + static_cast<size_t>(3 * (x - x0)) +
               i];
  };
  auto region = [&](int x, int y) { return sub_region(x, y, 1, 1); };
  for (int y = std::max(y0 - 1, 0); y <= y1; ++y) {
    for (int x = std::max(x0 - 1, 0); x <= x1; ++x) {
      const int r = region(x, y);
      if (r == region(x + 1, y) && r == region(x, y + 1)) continue;
      // Gradient of the anti-aliased boundary between this region and the neighbouring one
      // (coverage of this region minus coverage of the other) by derivative-of-Gaussian weights,
      // sigma 1 px. A third region meeting them at a corner takes no part.
      const int other = r != region(x + 1, y) ? region(x + 1, y) : region(x, y + 1);
      double gx = 0, gy = 0;
      for (int dy = -3; dy <= 3; ++dy) {
        for (int dx = -3; dx <= 3; ++dx) {
          int coverage = 0;
          for (int j = 0; j < 3; ++j) {
            for (int i = 0; i < 3; ++i) {
              const int q = sub_region(x + dx, y + dy, i, j);
              coverage += q == r ? 1 : (q == other ? -1 : 0);
            }
          }
          const double weight = coverage * std::exp(-(dx * dx + dy * dy) / 2.0);
          gx += dx * weight;
          gy += dy * weight;
        }
      }
      if (gx == 0 && gy == 0) continue;
      double angle = std::atan2(gy, gx);
      if (angle < 0) angle += M_PI;
      const int code = static_cast<int>(std::lround(angle * 256.0 / M_PI)) & 255;
      out.edge[static_cast<size_t>(y) * w + x] = 255;
      out.orientation[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(code);
    }
  }
  return out;
}

bool BruteForceVisible(const ViewCamera& view, const std::vector<PosedModel>& objects,
                       const Eigen::Vector3d& x_cam, double tolerance_mm,
                       double min_sin_incidence) {
  const double length = x_cam.norm();
  for (const PosedModel& o : objects) {
    const RigidTransform model_T_cam = (view.cam_T_left * o.cam_T_model).Inverse();
    const Eigen::Vector3d c = model_T_cam.t_mm.cast<double>();
    const Eigen::Vector3d d = model_T_cam.R.cast<double>() * x_cam;  // t = 1 at x
    const Model& m = *o.model;
    for (int f = 0; f < m.n_faces; ++f) {
      const ModelFace& mf = m.faces[f];
      const Eigen::Vector3d n(mf.normal[0], mf.normal[1], mf.normal[2]);
      const double nd = n.dot(d);
      if (std::fabs(nd) < 1e-12 || std::fabs(nd) < min_sin_incidence * d.norm()) continue;
      const double t = (mf.offset_mm - n.dot(c)) / nd;
      if (t > 0 && t * length < length - tolerance_mm && InsideByWinding(m, mf, c + t * d)) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace sh::testing
