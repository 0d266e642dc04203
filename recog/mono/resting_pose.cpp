#include "recog/mono/resting_pose.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

constexpr float kPlaneToleranceMm = 1e-3f;

float Cross2(const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Convex hull (counter-clockwise) of n points by the monotone chain; returns the hull size.
int ConvexHull2d(Eigen::Vector2f* p, int n, Eigen::Vector2f* hull) {
  std::sort(p, p + n, [](const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  int k = 0;
  for (int i = 0; i < n; ++i) {
    while (k >= 2 && Cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = p[i];
  }
  for (int i = n - 2, lower = k + 1; i >= 0; --i) {
    while (k >= lower && Cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0) --k;
    hull[k++] = p[i];
  }
  return std::max(0, k - 1);
}

}  // namespace

Eigen::Matrix3f RotationBetween(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const float c = a.dot(b);
  if (c < -0.999999f) {
    // Opposite: half a turn about any axis perpendicular to a.
    Eigen::Vector3f axis = a.cross(Eigen::Vector3f::UnitX());
    if (axis.norm() < 1e-3f) axis = a.cross(Eigen::Vector3f::UnitY());
    return Eigen::AngleAxisf(3.14159265f, axis.normalized()).toRotationMatrix();
  }
  // Rodrigues' formula with the unnormalised axis v = a x b (|v| = sin, c = cos).
  const Eigen::Vector3f v = a.cross(b);
  Eigen::Matrix3f vx;
  vx << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return Eigen::Matrix3f::Identity() + vx + vx * vx * (1.0f / (1.0f + c));
}

Eigen::Vector3f SolidCentroid(const Model& m) {
  // Sum over the fan triangles of every face of the tetrahedra they span with the origin:
  // signed volumes, so non-convex faces come out right.
  double volume = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    const Eigen::Vector3d a = m.corner(face.vertices[0]).cast<double>();
    for (int k = 1; k + 1 < face.n_vertices; ++k) {
      const Eigen::Vector3d b = m.corner(face.vertices[k]).cast<double>();
      const Eigen::Vector3d c = m.corner(face.vertices[k + 1]).cast<double>();
      const double v = a.dot(b.cross(c)) / 6.0;
      volume += v;
      moment += v * (a + b + c) / 4.0;
    }
  }
  if (!(std::fabs(volume) > 1e-9)) {
    Eigen::Vector3f c = Eigen::Vector3f::Zero();
    for (int i = 0; i < m.n_corners; ++i) c += m.corner(i);
    return m.n_corners > 0 ? Eigen::Vector3f(c / float(m.n_corners)) : c;
  }
  return (moment / volume).cast<float>();
}

Status ComputeStableFaces(const Model& m, float margin_mm, StableFaces* out) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "stable faces: no output");
  SH_RETURN_IF_ERROR(CheckModel(m));
  *out = StableFaces{};
  const Eigen::Vector3f centre = SolidCentroid(m);
  const int n = m.n_corners;
  // Hull planes examined (stable or not): each is examined once, from its first triple.
  constexpr int kMaxPlanes = 256;
  Eigen::Vector4f planes[kMaxPlanes];
  int n_planes = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        Eigen::Vector3f normal = (m.corner(j) - m.corner(i)).cross(m.corner(k) - m.corner(i));
        if (!(normal.norm() > 1e-3f)) continue;  // collinear
        normal.normalize();
        float offset = normal.dot(m.corner(i));
        // A hull plane has every corner on one side; orient it outwards.
        int above = 0, below = 0;
        for (int p = 0; p < n; ++p) {
          const float s = normal.dot(m.corner(p)) - offset;
          above += s > kPlaneToleranceMm;
          below += s < -kPlaneToleranceMm;
        }
        if (above > 0 && below > 0) continue;
        if (above > 0) {
          normal = -normal;
          offset = -offset;
        }
        bool seen = false;
        for (int q = 0; q < n_planes && !seen; ++q) {
          seen = (planes[q].head<3>() - normal).norm() < 1e-3f &&
                 std::fabs(planes[q].w() - offset) < 1e-2f;
        }
        if (seen) continue;
        if (n_planes == kMaxPlanes) {
          return Status::Error(StatusCode::kResourceExhausted,
                               "model '%.31s': convex hull has more than %d faces", m.name,
                               kMaxPlanes);
        }
        planes[n_planes++] = Eigen::Vector4f(normal.x(), normal.y(), normal.z(), offset);
        // The face polygon: hull of the corners in the plane, in plane coordinates.
        const Eigen::Vector3f u = (m.corner(j) - m.corner(i)).normalized();
        const Eigen::Vector3f w = normal.cross(u);
        Eigen::Vector2f pts[kMaxModelCorners], hull[2 * kMaxModelCorners];
        int n_pts = 0;
        for (int p = 0; p < n; ++p) {
          if (std::fabs(normal.dot(m.corner(p)) - offset) <= kPlaneToleranceMm) {
            pts[n_pts++] = {u.dot(m.corner(p)), w.dot(m.corner(p))};
          }
        }
        const int h = ConvexHull2d(pts, n_pts, hull);
        if (h < 3) continue;
        // Stable: the centre of mass projects inside the polygon by at least the margin.
        const Eigen::Vector2f c(u.dot(centre), w.dot(centre));
        bool inside = true;
        float area = 0;
        for (int e = 0; e < h; ++e) {
          const Eigen::Vector2f a = hull[e], b = hull[(e + 1) % h];
          const float len = (b - a).norm();
          area += 0.5f * Cross2(a, b);
          if (!(len > 0.0f) || Cross2(b - a, c - a) / len < margin_mm) inside = false;
        }
        if (!inside) continue;
        if (out->count == kMaxStableFaces) {
          return Status::Error(StatusCode::kResourceExhausted,
                               "model '%.31s' has more than %d stable faces", m.name,
                               kMaxStableFaces);
        }
        out->faces[out->count++] = {normal, offset, std::fabs(area)};
      }
    }
  }
  return Status::Ok();
}

Eigen::Matrix3f RestingRotation(const StableFace& f) {
  return RotationBetween(f.normal_model, Eigen::Vector3f(0, 0, -1));
}

RigidTransform RestingTransform(const TablePlane& table, const StableFaces& faces,
                                const RestingPose& pose) {
  const StableFace& f = faces.faces[pose.face];
  RigidTransform table_T_model;
  table_T_model.R =
      Eigen::AngleAxisf(pose.heading_rad, Eigen::Vector3f::UnitZ()).toRotationMatrix() *
      RestingRotation(f);
  // Points of the face (normal . x = offset) end up at table height -offset + t_z: t_z = offset.
  table_T_model.t_mm = Eigen::Vector3f(pose.x_mm, pose.y_mm, f.offset_mm);
  return table.cam_T_table * table_T_model;
}

bool RestingPoseOnFace(const TablePlane& table, const StableFaces& faces, int face,
                       const RigidTransform& cam_T_model, RestingPose* out) {
  const RigidTransform table_T_cam = table.cam_T_table.Inverse();
  const RigidTransform table_T_model = table_T_cam * cam_T_model;
  const StableFace& f = faces.faces[face];
  const Eigen::Matrix3f R =
      RotationBetween(table_T_model.R * f.normal_model, Eigen::Vector3f(0, 0, -1)) *
      table_T_model.R;
  const Eigen::Matrix3f heading = R * RestingRotation(f).transpose();
  // The model origin stays on its viewing ray, at its resting height above the table.
  const Eigen::Vector3f centre = table_T_cam.t_mm;
  const Eigen::Vector3f ray = table_T_model.t_mm - centre;
  if (!(std::fabs(ray.z()) > 1e-6f)) return false;
  const float lambda = (f.offset_mm - centre.z()) / ray.z();
  if (!(lambda > 0.0f) || !std::isfinite(lambda)) return false;
  const Eigen::Vector3f p = centre + lambda * ray;
  out->face = face;
  out->heading_rad = std::atan2(heading(1, 0), heading(0, 0));
  out->x_mm = p.x();
  out->y_mm = p.y();
  return true;
}

bool NearestRestingPose(const TablePlane& table, const StableFaces& faces,
                        const RigidTransform& cam_T_model, float max_tilt_deg, RestingPose* out,
                        float* tilt_deg) {
  if (faces.count == 0) return false;
  const Eigen::Matrix3f table_R_model = table.cam_T_table.R.transpose() * cam_T_model.R;
  int best = -1;
  float best_cos = -2.0f;
  for (int f = 0; f < faces.count; ++f) {
    const float c = -(table_R_model * faces.faces[f].normal_model).z();
    if (c > best_cos) best_cos = c, best = f;
  }
  const float tilt = std::acos(std::max(-1.0f, std::min(1.0f, best_cos))) * 57.2957795f;
  if (tilt_deg != nullptr) *tilt_deg = tilt;
  if (!(tilt <= max_tilt_deg)) return false;
  return RestingPoseOnFace(table, faces, best, cam_T_model, out);
}

bool RestingPoseFromCorners(const TablePlane& table, const StableFaces& faces, int face,
                            const Eigen::Vector3f& a_model, const Eigen::Vector3f& b_model,
                            const Eigen::Vector3f& ray_a, const Eigen::Vector3f& ray_b,
                            float min_offset_mm, RestingPose* out, float* length_ratio) {
  const StableFace& f = faces.faces[face];
  const RigidTransform table_T_cam = table.cam_T_table.Inverse();
  const Eigen::Vector3f centre = table_T_cam.t_mm;
  // Heights of the corners above the table when resting on f: offset - normal . x.
  const Eigen::Vector3f corners[2] = {a_model, b_model};
  const Eigen::Vector3f rays[2] = {table_T_cam.R * ray_a, table_T_cam.R * ray_b};
  Eigen::Vector3f on_table[2];
  for (int k = 0; k < 2; ++k) {
    const float height = f.offset_mm - f.normal_model.dot(corners[k]);
    if (!(std::fabs(rays[k].z()) > 1e-6f)) return false;
    const float lambda = (height - centre.z()) / rays[k].z();
    if (!(lambda > 0.0f) || !std::isfinite(lambda)) return false;
    on_table[k] = centre + lambda * rays[k];
  }
  const Eigen::Matrix3f face_R = RestingRotation(f);
  const Eigen::Vector2f model_offset = (face_R * (b_model - a_model)).head<2>();
  const Eigen::Vector2f seen_offset = (on_table[1] - on_table[0]).head<2>();
  if (!(model_offset.norm() >= min_offset_mm)) return false;
  if (length_ratio != nullptr) *length_ratio = seen_offset.norm() / model_offset.norm();
  const float heading =
      std::atan2(seen_offset.y(), seen_offset.x()) - std::atan2(model_offset.y(), model_offset.x());
  const Eigen::Matrix3f R =
      Eigen::AngleAxisf(heading, Eigen::Vector3f::UnitZ()).toRotationMatrix() * face_R;
  // Position: the two corners' table points, averaged.
  const Eigen::Vector2f t =
      0.5f * ((on_table[0] - R * a_model) + (on_table[1] - R * b_model)).head<2>();
  out->face = face;
  out->heading_rad = heading;
  out->x_mm = t.x();
  out->y_mm = t.y();
  return true;
}

}  // namespace sh
