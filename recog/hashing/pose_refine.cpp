#include "recog/hashing/pose_refine.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "recog/hashing/scene_grid.hpp"
#include "recog/model/model_features.hpp"

namespace sh {
namespace {

Eigen::Matrix3f Skew(const Eigen::Vector3f& v) {
  Eigen::Matrix3f m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

struct EdgeGeometry {
  Eigen::Vector3f centre, dir;
  float length;
};

EdgeGeometry ModelEdgeGeometry(const Model& m, int e) {
  const Eigen::Vector3f a = m.corner(m.edges[e].a), b = m.corner(m.edges[e].b);
  const float length = (b - a).norm();
  return {0.5f * (a + b), (b - a) / length, length};
}

// Accumulates one weighted residual block into the normal equations.
template <int N>
void Accumulate(const Eigen::Matrix<float, N, 6>& J, const Eigen::Matrix<float, N, 1>& r,
                float weight, Eigen::Matrix<float, 6, 6>& H, Eigen::Matrix<float, 6, 1>& g,
                float& cost) {
  H.noalias() += weight * J.transpose() * J;
  g.noalias() += weight * J.transpose() * r;
  cost += weight * r.squaredNorm();
}

}  // namespace

void SelectCorrespondences(const RefineInput& in, const RigidTransform& cam_T_model, float gate_mm,
                           Correspondences* out) {
  const Model& m = *in.model;
  // Tessellation vertices and rim chords of curved surfaces are nothing the scene's corners and
  // lines stand for: they match nothing.
  const ModelFeatures features = FeaturesOf(m);
  out->matched_points = out->matched_lines = 0;
  for (int i = 0; i < m.n_corners; ++i) {
    out->point_of_corner[i] = -1;
    if (!features.corner(i)) continue;
    const Eigen::Vector3f x = cam_T_model * m.corner(i);
    int best = -1;
    float best_d2 = 1e30f;
    in.point_grid->ForEachNear(x, gate_mm, [&](int j) {
      if (!in.point_active[j]) return;
      const float d2 = (in.scene->points[j].p_mm - x).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = j;
    });
    out->point_of_corner[i] = int16_t(best);
    out->matched_points += best >= 0;
  }
  const float gate2 = gate_mm * gate_mm;
  // Only scene lines whose supported segment comes near the posed model can match its edges:
  // collect them once instead of testing every scene line for every edge.
  float radius = 0.0f;
  for (int i = 0; i < m.n_corners; ++i) radius = std::max(radius, m.corner(i).norm());
  const float reach = radius + gate_mm;
  const Eigen::Vector3f object_centre = cam_T_model.t_mm;
  int16_t near[kMaxSceneLines];
  int n_near = 0;
  for (size_t j = 0; j < in.scene->lines.size(); ++j) {
    if (!in.line_active[j]) continue;
    const SceneLine& l = in.scene->lines[j];
    const Eigen::Vector3f ab = l.b_mm - l.a_mm;
    const float t = std::clamp((object_centre - l.a_mm).dot(ab) / std::max(ab.squaredNorm(), 1e-6f),
                               0.0f, 1.0f);
    if ((l.a_mm + t * ab - object_centre).squaredNorm() <= reach * reach)
      near[n_near++] = int16_t(j);
  }
  for (int e = 0; e < m.n_edges; ++e) {
    out->line_of_edge[e] = -1;
    if (!features.line(e)) continue;
    const EdgeGeometry g = ModelEdgeGeometry(m, e);
    const Eigen::Vector3f centre = cam_T_model * g.centre, dir = cam_T_model.Rotate(g.dir);
    int best = -1;
    float best_d2 = gate2;
    for (int k = 0; k < n_near; ++k) {
      const int j = near[k];
      const SceneLine& l = in.scene->lines[j];
      const Eigen::Vector3f v = l.direction();
      const float d2 = SegmentLineDistance2(centre, dir, g.length, l.a_mm, v);
      if (d2 < best_d2) best_d2 = d2, best = j;
    }
    out->line_of_edge[e] = int16_t(best);
    out->matched_lines += best >= 0;
  }
}

RefineResult RefinePose(const RefineInput& in, const RigidTransform& initial,
                        const RefineConfig& config) {
  const Model& m = *in.model;
  RefineResult result;
  result.cam_T_model = initial;
  RigidTransform& T = result.cam_T_model;
  const float w_point = 1.0f / (in.sigma_point_mm * in.sigma_point_mm);
  const float w_line = 1.0f / (in.sigma_line_mm * in.sigma_line_mm);
  const float gate_mm = config.gate_sigmas * std::max(in.sigma_point_mm, in.sigma_line_mm);
  float cost = 0.0f;
  int residual_count = 0;
  for (int round = 0; round < config.rounds; ++round) {
    SelectCorrespondences(in, T, gate_mm, &result.matches);
    const Correspondences& c = result.matches;
    // Fewer than three constraints cannot fix 6 parameters: keep the pose.
    if (c.matched_points + 2 * c.matched_lines < 3) break;
    for (int it = 0; it < config.iterations; ++it) {
      // Rotations are parametrised about the object's own origin (t): x' = exp(w)(x - t) + t + d.
      // About the camera origin, half a metre away, rotation and translation would be nearly
      // collinear and the normal equations badly conditioned.
      const Eigen::Vector3f centre = T.t_mm;
      Eigen::Matrix<float, 6, 6> H = Eigen::Matrix<float, 6, 6>::Zero();
      Eigen::Matrix<float, 6, 1> g = Eigen::Matrix<float, 6, 1>::Zero();
      cost = 0.0f;
      residual_count = 0;
      for (int i = 0; i < m.n_corners; ++i) {
        if (c.point_of_corner[i] < 0) continue;
        const Eigen::Vector3f x = T * m.corner(i);
        Eigen::Matrix<float, 3, 6> J;
        J.leftCols<3>() = -Skew(x - centre);
        J.rightCols<3>().setIdentity();
        const Eigen::Vector3f r = x - in.scene->points[c.point_of_corner[i]].p_mm;
        Accumulate<3>(J, r, w_point, H, g, cost);
        ++residual_count;
      }
      for (int e = 0; e < m.n_edges; ++e) {
        if (c.line_of_edge[e] < 0) continue;
        const EdgeGeometry eg = ModelEdgeGeometry(m, e);
        const SceneLine& l = in.scene->lines[c.line_of_edge[e]];
        const Eigen::Vector3f v = l.direction();
        const Eigen::Matrix3f P = Eigen::Matrix3f::Identity() - v * v.transpose();
        const Eigen::Vector3f x0 = T * eg.centre, u = T.Rotate(eg.dir);
        const float k = eg.length * 0.28867513f;  // L / sqrt(12)
        Eigen::Matrix<float, 6, 6> J;
        J.topLeftCorner<3, 3>() = -P * Skew(x0 - centre);
        J.topRightCorner<3, 3>() = P;
        J.bottomLeftCorner<3, 3>() = -k * Skew(v) * Skew(u);
        J.bottomRightCorner<3, 3>().setZero();
        Eigen::Matrix<float, 6, 1> r;
        r.head<3>() = P * (x0 - l.a_mm);
        r.tail<3>() = k * v.cross(u);
        Accumulate<6>(J, r, w_line, H, g, cost);
        ++residual_count;
      }
      // A trace of Levenberg damping keeps under-constrained directions (e.g. all edges
      // parallel) from running away without slowing the well-constrained ones.
      H.diagonal().array() += 1e-7f * H.trace() + 1e-9f;
      const Eigen::Matrix<float, 6, 1> xi = -H.ldlt().solve(g);
      if (!xi.allFinite()) break;
      const Eigen::Vector3f w = xi.head<3>();
      const float angle = w.norm();
      const Eigen::Matrix3f dR = angle > 1e-9f
                                     ? Eigen::AngleAxisf(angle, w / angle).toRotationMatrix()
                                     : Eigen::Matrix3f::Identity();
      T.R = dR * T.R;
      T.t_mm = centre + xi.tail<3>();
      if (angle < 1e-6f && xi.tail<3>().norm() < 1e-4f) break;
    }
    Orthonormalize(T);
  }
  SelectCorrespondences(in, T, gate_mm, &result.matches);
  const float sigma2 = in.sigma_point_mm * in.sigma_point_mm;
  result.rms_mm = residual_count > 0 ? std::sqrt(cost * sigma2 / float(residual_count)) : 0.0f;
  return result;
}

}  // namespace sh
