#include "recog/verify/edge_refine.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>

#include "recog/base/angles.hpp"
#include "recog/verify/verify.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

constexpr float kDelta = 1e-3f;  // finite-difference step: rad for rotation, mm for translation

bool ProjectF(const CameraIntrinsics& cam, const Eigen::Vector3f& x_cam, Eigen::Vector2f* px) {
  Eigen::Vector2d p;
  if (!ProjectToPixel(cam, x_cam.cast<double>(), &p)) return false;
  *px = p.cast<float>();
  return true;
}

// The finite-difference steps of the three rotation parameters: turns by kDelta about the left
// camera's axes, as matrices (an angle-axis rotation applied to a vector is its matrix times the
// vector, so these give the same products as building the rotation per sample).
struct StepTurns {
  Eigen::Matrix3f R[3];
  StepTurns() {
    for (int k = 0; k < 3; ++k) R[k] = Eigen::AngleAxisf(kDelta, Eigen::Vector3f::Unit(k)).matrix();
  }
};

// The six pose parameters, each stepped by kDelta, applied to a left-frame point of the object
// posed at `origin`: a rotation about the model origin, then a translation.
Eigen::Vector3f Perturb(const Eigen::Vector3f& x, const Eigen::Vector3f& origin, int k,
                        const StepTurns& turns) {
  if (k >= 3) {
    Eigen::Vector3f y = x;
    y[k - 3] += kDelta;
    return y;
  }
  return origin + turns.R[k] * (x - origin);
}

struct Accumulated {
  Eigen::Matrix<float, 6, 6> H = Eigen::Matrix<float, 6, 6>::Zero();
  Eigen::Matrix<float, 6, 1> g = Eigen::Matrix<float, 6, 1>::Zero();
  int found = 0;
  float inliers = 0;
  double sum_r2 = 0;
};

// Signed distance along `normal` from `p` to the nearest edge pixel perpendicular to the edge,
// within search_px; false if there is none.
bool NearestEdge(const ConstEdgeMapView& edges, const Eigen::Vector2f& p,
                 const Eigen::Vector2f& normal, float search_px, float min_abs_cos, float* r) {
  const int w = edges.edge.width, h = edges.edge.height;
  const int steps = static_cast<int>(search_px * 2.0f);
  for (int step = 0; step <= 2 * steps; ++step) {
    const int half_steps = (step + 1) / 2;  // 0, 1, 1, 2, 2, ...: out from p on both sides
    const float s = 0.5f * static_cast<float>(half_steps) * ((step & 1) ? 1.0f : -1.0f);
    const Eigen::Vector2f q = p + s * normal;
    const int qx = static_cast<int>(std::floor(q.x() + 0.5f));
    const int qy = static_cast<int>(std::floor(q.y() + 0.5f));
    if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
    if (edges.edge.row(qy)[qx] == 0) continue;
    // Orientation step to gradient angle in [0, pi) (edge_map.hpp: 256 steps per half turn).
    const float angle = static_cast<float>(edges.orientation.row(qy)[qx]) * (kPi / 256.0f);
    if (std::fabs(std::cos(angle) * normal.x() + std::sin(angle) * normal.y()) < min_abs_cos) {
      continue;
    }
    // The pixel centre's offset along the normal: finer than the search step.
    *r = normal.dot(Eigen::Vector2f(float(qx), float(qy)) - p);
    return true;
  }
  return false;
}

Status Accumulate(const ViewCamera& view, const ConstEdgeMapView& edges, const Model& model,
                  const RigidTransform& pose, const PosedModel* occluders, size_t n_occluders,
                  const EdgeRefineConfig& config, Accumulated* acc) {
  VisibleEdgeSet visible;
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(view, {&model, pose}, occluders, n_occluders,
                                         config.sample_step_px, 1.0f, &visible));
  const CameraIntrinsics& cam = view.intrinsics;
  const RigidTransform left_T_cam = view.cam_T_left.Inverse();
  const float min_abs_cos = std::cos(config.max_angle_deg * kPi / 180.0f);
  const StepTurns turns;
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    for (int r = 0; r < ve.n_runs; ++r) {
      for (int i = ve.runs[r].first; i < ve.runs[r].end; ++i) {
        const float s = SampleImageFraction(i, ve.n_samples);
        const Eigen::Vector3f x_cam = PointAtImageFraction(ve, s);
        const Eigen::Vector3f ahead_cam = PointAtImageFraction(ve, std::min(1.0f, s + 0.01f));
        Eigen::Vector2f p, ahead;
        if (!ProjectF(cam, x_cam, &p) || !ProjectF(cam, ahead_cam, &ahead)) continue;
        Eigen::Vector2f dir = ahead - p;
        if (!(dir.norm() > 1e-6f)) continue;
        dir.normalize();
        const Eigen::Vector2f normal(-dir.y(), dir.x());
        float res = 0;
        if (!NearestEdge(edges, p, normal, config.search_px, min_abs_cos, &res)) continue;
        // d residual / d parameter: the sample's image motion along the normal.
        const Eigen::Vector3f x_left = left_T_cam * x_cam;
        Eigen::Matrix<float, 6, 1> J;
        bool ok = true;
        for (int j = 0; j < 6 && ok; ++j) {
          Eigen::Vector2f moved;
          ok = ProjectF(cam, view.cam_T_left * Perturb(x_left, pose.t_mm, j, turns), &moved);
          // The residual is edge minus sample: it shrinks as the sample moves towards the edge.
          J[j] = -normal.dot(moved - p) / kDelta;
        }
        if (!ok) continue;
        const float a = std::fabs(res);
        const float w = a <= config.huber_px ? 1.0f : config.huber_px / a;
        acc->H += w * J * J.transpose();
        acc->g += w * J * res;
        ++acc->found;
        acc->inliers += a <= config.inlier_px ? 1.0f : 0.0f;
        acc->sum_r2 += double{res} * res;
      }
    }
  }
  return Status::Ok();
}

Status Measure(const StereoCalibration& calib, const ConstEdgeMapView* maps[2], const Model& model,
               const RigidTransform& pose, const PosedModel* occluders, size_t n_occluders,
               const EdgeRefineConfig& config, Accumulated* acc) {
  *acc = Accumulated{};
  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  for (int c = 0; c < 2; ++c) {
    SH_RETURN_IF_ERROR(
        Accumulate(views[c], *maps[c], model, pose, occluders, n_occluders, config, acc));
  }
  return Status::Ok();
}

}  // namespace

Status RefinePoseOnEdges(const StereoCalibration& calib, const ConstEdgeMapView& left_edges,
                         const ConstEdgeMapView& right_edges, const Model& model,
                         const PosedModel* occluders, size_t n_occluders,
                         const EdgeRefineConfig& config, RigidTransform* pose,
                         EdgeRefineResult* result) {
  *result = EdgeRefineResult{};
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.left, left_edges));
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.right, right_edges));
  SH_RETURN_IF_ERROR(CheckModel(model));
  const ConstEdgeMapView* maps[2] = {&left_edges, &right_edges};
  const RigidTransform start = *pose;
  RigidTransform current = start;
  Accumulated acc;
  SH_RETURN_IF_ERROR(Measure(calib, maps, model, current, occluders, n_occluders, config, &acc));
  result->inliers_before = acc.inliers;
  result->rms_px_before = acc.found ? static_cast<float>(std::sqrt(acc.sum_r2 / acc.found)) : 0;
  if (acc.found < config.min_samples) return Status::Ok();
  for (int it = 0; it < config.iterations; ++it) {
    // Levenberg-style damping keeps a weakly constrained direction (an edge seen end-on) still.
    Eigen::Matrix<float, 6, 6> H = acc.H;
    H.diagonal() += 1e-3f * H.diagonal().cwiseMax(1.0f);
    const Eigen::Matrix<float, 6, 1> step = H.ldlt().solve(-acc.g);
    if (!step.allFinite()) break;
    const Eigen::Vector3f w = step.head<3>();
    const float angle = w.norm();
    RigidTransform next = current;
    if (angle > 0) next.R = Eigen::AngleAxisf(angle, w / angle) * current.R;
    next.t_mm = current.t_mm + step.tail<3>();
    Orthonormalize(next);
    current = next;
    SH_RETURN_IF_ERROR(Measure(calib, maps, model, current, occluders, n_occluders, config, &acc));
    if (acc.found < config.min_samples) break;
    if (step.head<3>().norm() < 1e-5f && step.tail<3>().norm() < 1e-3f) break;
  }
  result->samples = acc.found;
  result->inliers_after = acc.inliers;
  result->rms_px_after = acc.found ? static_cast<float>(std::sqrt(acc.sum_r2 / acc.found)) : 0;
  const float shift = (current.t_mm - start.t_mm).norm();
  const float turn = RotationAngleDeg(current.R * start.R.transpose());
  if (acc.found >= config.min_samples && acc.inliers >= result->inliers_before &&
      shift <= config.max_shift_mm && turn <= config.max_turn_deg) {
    *pose = current;
    result->refined = true;
  }
  return Status::Ok();
}

}  // namespace sh
