#include "recog/pipeline/table_estimate.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "recog/base/angles.hpp"

namespace sh {
namespace {

struct Plane {
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();  // unit, towards the cameras
  float d = 0;                                    // height of x: up . x + d
  float Height(const Eigen::Vector3f& x) const { return up.dot(x) + d; }
};

// How an object sits on a plane: its lowest corner's height and its corners within tol.
struct Contact {
  float lowest = 0;
  uint32_t in_plane = 0;
};

Contact ContactOf(const Model& model, const RigidTransform& cam_T_model, const Plane& plane,
                  float tol) {
  Contact c;
  c.lowest = 1e30f;
  for (int k = 0; k < model.n_corners; ++k) {
    const float h = plane.Height(cam_T_model * model.corner(k));
    c.lowest = std::min(c.lowest, h);
    if (std::fabs(h) <= tol) ++c.in_plane;
  }
  return c;
}

bool Rests(const Contact& c, float tol) { return std::fabs(c.lowest) <= tol && c.in_plane >= 3; }

}  // namespace

const char* TableEstimateOutcomeName(TableEstimateOutcome o) {
  switch (o) {
    case TableEstimateOutcome::kAccepted:
      return "accepted";
    case TableEstimateOutcome::kDisabled:
      return "disabled";
    case TableEstimateOutcome::kTooFewObjects:
      return "too_few_objects";
    case TableEstimateOutcome::kNoAgreement:
      return "no_agreement";
  }
  return "unknown";
}

Status CheckTableEstimateConfig(const TableEstimateConfig& c) {
  if (!(c.tolerance_mm > 0 && std::isfinite(c.tolerance_mm)) || c.min_objects < 1 ||
      !(c.max_view_angle_deg > 0 && c.max_view_angle_deg <= 90) ||
      !(c.min_height_mm >= 0 && std::isfinite(c.min_height_mm))) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "table estimate: tolerance_mm %g must be finite and positive, min_objects "
                         "%u at least 1, max_view_angle_deg %g in (0, 90], min_height_mm %g "
                         "finite and not negative",
                         c.tolerance_mm, c.min_objects, c.max_view_angle_deg, c.min_height_mm);
  }
  return Status::Ok();
}

void EstimateTableFromObjects(const RecognizedObject* objects, const Model* const* models, size_t n,
                              const TableEstimateConfig& config, TableEstimate* out) {
  *out = TableEstimate{};
  if (!config.enabled) return;
  out->objects = static_cast<uint32_t>(n);
  if (n < config.min_objects || n < 1) {
    out->outcome = TableEstimateOutcome::kTooFewObjects;
    return;
  }
  const float tol = config.tolerance_mm;
  const float cos_view = std::cos(config.max_view_angle_deg * kDegToRad);
  Plane best;
  uint32_t best_resting = 0;
  float best_error = 0;
  for (size_t i = 0; i < n; ++i) {
    const Model& m = *models[i];
    const RigidTransform& T = objects[i].cam_T_model;
    for (int f = 0; f < m.n_faces; ++f) {
      if (m.faces[f].n_vertices < 3) continue;
      // The resting face's outward normal points down, into the table.
      Plane p;
      p.up = -(T.R * m.face_normal(f)).normalized();
      const Eigen::Vector3f on = T * m.corner(m.faces[f].vertices[0]);
      p.d = -p.up.dot(on);
      // Seen from above: the camera (origin) at height d, the normal facing it.
      if (p.d < config.min_height_mm || -p.up.dot(on) < cos_view * on.norm()) continue;
      uint32_t resting = 0;
      float error = 0;
      for (size_t j = 0; j < n; ++j) {
        const Contact c = ContactOf(*models[j], objects[j].cam_T_model, p, tol);
        if (!Rests(c, tol)) continue;
        ++resting;
        error += std::fabs(c.lowest);
      }
      if (resting > best_resting || (resting == best_resting && error < best_error)) {
        best = p;
        best_resting = resting;
        best_error = error;
      }
    }
  }
  if (best_resting < config.min_objects) {
    out->outcome = TableEstimateOutcome::kNoAgreement;
    out->resting = best_resting;
    return;
  }
  // The corners in the plane of the objects resting on it: the least-squares fit's points.
  const auto for_each_contact = [&](auto&& visit) {
    for (size_t j = 0; j < n; ++j) {
      const Model& m = *models[j];
      const RigidTransform& T = objects[j].cam_T_model;
      if (!Rests(ContactOf(m, T, best, tol), tol)) continue;
      for (int k = 0; k < m.n_corners; ++k) {
        const Eigen::Vector3f x = T * m.corner(k);
        if (std::fabs(best.Height(x)) <= tol) visit(x);
      }
    }
  };
  // Least squares plane through them (double sums).
  double count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  for_each_contact([&](const Eigen::Vector3f& x) {
    const Eigen::Vector3d q = x.cast<double>();
    count += 1;
    sum += q;
    outer += q * q.transpose();
  });
  const Eigen::Vector3d mean = sum / count;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(outer / count - mean * mean.transpose());
  Plane fit = best;
  if (eig.info() == Eigen::Success) {
    // Smallest eigenvalue first: its vector is the normal, oriented like the candidate's.
    Eigen::Vector3f up = eig.eigenvectors().col(0).cast<float>().normalized();
    if (up.dot(best.up) < 0) up = -up;
    fit.up = up;
    fit.d = -up.dot(mean.cast<float>());
  }
  double d2 = 0;
  for_each_contact([&](const Eigen::Vector3f& x) { d2 += double(fit.Height(x)) * fit.Height(x); });
  // The table frame: z the normal, origin the resting corners' centre in the plane.
  const Eigen::Vector3f z = fit.up;
  const Eigen::Vector3f helper =
      std::fabs(z.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f x = (helper - helper.dot(z) * z).normalized();
  const Eigen::Vector3f centre = mean.cast<float>();
  out->left_T_table.R.col(0) = x;
  out->left_T_table.R.col(1) = z.cross(x);
  out->left_T_table.R.col(2) = z;
  out->left_T_table.t_mm = centre - fit.Height(centre) * z;
  out->resting = best_resting;
  out->corners = static_cast<uint32_t>(count);
  out->rms_mm = static_cast<float>(std::sqrt(d2 / count));
  out->outcome = TableEstimateOutcome::kAccepted;
}

uint32_t CountResting(const RecognizedObject* objects, const Model* const* models, size_t n,
                      const RigidTransform& left_T_table, float tolerance_mm) {
  Plane table;
  table.up = left_T_table.R.col(2);
  table.d = -table.up.dot(left_T_table.t_mm);
  uint32_t resting = 0;
  for (size_t i = 0; i < n; ++i) {
    if (Rests(ContactOf(*models[i], objects[i].cam_T_model, table, tolerance_mm), tolerance_mm)) {
      ++resting;
    }
  }
  return resting;
}

float LowestCornerHeightMm(const Model& model, const RigidTransform& cam_T_model,
                           const RigidTransform& left_T_table) {
  const Eigen::Vector3f up = left_T_table.R.col(2);
  const float top = up.dot(left_T_table.t_mm);
  float lowest = 1e30f;
  for (int i = 0; i < model.n_corners; ++i) {
    lowest = std::min(lowest, up.dot(cam_T_model * model.corner(i)) - top);
  }
  return lowest;
}

uint32_t KeepOverTable(const RigidTransform& left_T_table, float below_mm, float above_mm,
                       float min_length_mm, Scene* scene) {
  const Eigen::Vector3f up = left_T_table.R.col(2);
  const float top = up.dot(left_T_table.t_mm);
  const auto height = [&](const Eigen::Vector3f& p) { return up.dot(p) - top; };
  uint32_t dropped = 0;
  size_t kept = 0;
  for (size_t i = 0; i < scene->points.size(); ++i) {
    const float h = height(scene->points[i].p_mm);
    if (h < -below_mm || h > above_mm) {
      ++dropped;
      continue;
    }
    scene->points[kept++] = scene->points[i];
  }
  (void)scene->points.resize(kept);
  kept = 0;
  for (size_t i = 0; i < scene->lines.size(); ++i) {
    SceneLine l = scene->lines[i];
    // Clip the segment a + s (b - a), s in [0, 1], to the slab -below..above.
    const float ha = height(l.a_mm), hb = height(l.b_mm);
    float s0 = 0.0f, s1 = 1.0f;
    const float dh = hb - ha;
    if (std::fabs(dh) < 1e-6f) {
      if (ha < -below_mm || ha > above_mm) s1 = -1.0f;
    } else {
      const float lo = (-below_mm - ha) / dh, hi = (above_mm - ha) / dh;
      s0 = std::max(s0, std::min(lo, hi));
      s1 = std::min(s1, std::max(lo, hi));
    }
    const float length = l.length_mm();
    if (!(s1 > s0) || (s1 - s0) * length < min_length_mm) {
      ++dropped;
      continue;
    }
    if (s0 > 0.0f || s1 < 1.0f) {
      const Eigen::Vector3f a = l.a_mm, u = l.b_mm - l.a_mm;
      l.a_mm = a + s0 * u;
      l.b_mm = a + s1 * u;
      // Quality is the supported length by default: keep the share inside the slab.
      l.quality *= s1 - s0;
    }
    scene->lines[kept++] = l;
  }
  (void)scene->lines.resize(kept);
  return dropped;
}

}  // namespace sh
