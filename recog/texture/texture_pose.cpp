#include "recog/texture/texture_pose.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sh::texture {
namespace {

Eigen::Matrix3d Rodrigues(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// A large residual for an observation that does not project (behind a camera, parallel ray):
// keeps the count of residuals fixed so that finite differences stay aligned.
constexpr double kInvalidResidual = 1e3;

}  // namespace

size_t TexturePoseRefiner::Residuals(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                     double* out) const {
  const StereoCalibration& c = *calib_;
  size_t k = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    if (!active_[i]) continue;
    const PoseFeatureObservation& o = features_[i];
    Eigen::Vector2d px;
    if (ProjectToPixel(c.left, R * o.model_mm + t, &px)) {
      out[k++] = (px.x() - o.left_px.x()) / o.sigma_px;
      out[k++] = (px.y() - o.left_px.y()) / o.sigma_px;
    } else {
      out[k++] = kInvalidResidual;
      out[k++] = kInvalidResidual;
    }
  }
  for (size_t i = 0; i < n_stereo_; ++i) {
    if (!active_[kMaxPoseObservations + i]) continue;
    const PoseStereoObservation& o = stereo_[i];
    // The face plane in the camera: n_c . x = d + n_c . t.
    const Eigen::Vector3d n = R * o.plane_normal_model;
    const double d = o.plane_d_mm + n.dot(t);
    const double denom = n.dot(rays_[i]);
    Eigen::Vector2d px;
    bool ok = std::fabs(denom) > 1e-9;
    if (ok) {
      const double depth = d / denom;
      ok = depth > 0 &&
           ProjectToPixel(c.right, c.right_R_left * (depth * rays_[i]) + c.right_t_left_mm, &px);
    }
    if (ok) {  // unweighted: Solve scales the stereo block by 1 / stereo_sigma_px
      out[k++] = px.x() - o.right_px.x();
      out[k++] = px.y() - o.right_px.y();
    } else {
      out[k++] = kInvalidResidual;
      out[k++] = kInvalidResidual;
    }
  }
  return k;
}

bool TexturePoseRefiner::Solve(const PoseRefineConfig& config, Eigen::Matrix3d* R,
                               Eigen::Vector3d* t) {
  // Parameters: rotation increment w (about the model's current centre, so that rotation and
  // translation decouple) and translation increment v.
  const double stereo_w = 1.0 / config.stereo_sigma_px;
  for (int it = 0; it < config.iterations; ++it) {
    const size_t m = Residuals(*R, *t, residuals_);
    if (m < 6) return false;
    // Scale the stereo residuals (they follow the feature residuals).
    size_t n_feat = 0;
    for (size_t i = 0; i < n_features_; ++i) n_feat += active_[i] ? 2 : 0;
    for (size_t k = n_feat; k < m; ++k) residuals_[k] *= stereo_w;
    Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();
    // Numerical Jacobian, column by column, then the normal equations.
    constexpr double kRotStep = 1e-5;    // rad
    constexpr double kTransStep = 1e-3;  // mm
    double(*jac)[4 * kMaxPoseObservations] = jacobian_;
    for (int p = 0; p < 6; ++p) {
      Eigen::Matrix3d R2 = *R;
      Eigen::Vector3d t2 = *t;
      double step;
      if (p < 3) {
        Eigen::Vector3d w = Eigen::Vector3d::Zero();
        w[p] = kRotStep;
        R2 = Rodrigues(w) * *R;  // about the model origin (at t): decoupled from t
        step = kRotStep;
      } else {
        t2[p - 3] += kTransStep;
        step = kTransStep;
      }
      Residuals(R2, t2, shifted_);
      for (size_t k = n_feat; k < m; ++k) shifted_[k] *= stereo_w;
      for (size_t k = 0; k < m; ++k) jac[p][k] = (shifted_[k] - residuals_[k]) / step;
    }
    for (size_t k = 0; k < m; ++k) {
      Eigen::Matrix<double, 6, 1> row;
      for (int p = 0; p < 6; ++p) row[p] = jac[p][k];
      jtj += row * row.transpose();
      jtr += row * residuals_[k];
    }
    const Eigen::Matrix<double, 6, 1> delta = -jtj.ldlt().solve(jtr);
    if (!delta.allFinite()) return false;
    *R = Rodrigues(delta.head<3>()) * *R;
    *t += delta.tail<3>();
    if (delta.head<3>().norm() < 1e-7 && delta.tail<3>().norm() < 1e-5) break;
  }
  return R->allFinite() && t->allFinite();
}

bool TexturePoseRefiner::Refine(const StereoCalibration& calib,
                                const PoseFeatureObservation* features, size_t n_features,
                                const PoseStereoObservation* stereo, size_t n_stereo,
                                const PoseRefineConfig& config, RigidTransform* cam_T_model,
                                PoseRefineStats* stats) {
  *stats = {};
  calib_ = &calib;
  features_ = features;
  stereo_ = stereo;
  n_features_ = std::min(n_features, kMaxPoseObservations);
  n_stereo_ = std::min(n_stereo, kMaxPoseObservations);
  if (2 * (n_features_ + n_stereo_) < 6) return false;
  for (size_t i = 0; i < n_features_; ++i) active_[i] = true;
  for (size_t i = 0; i < n_stereo_; ++i) {
    active_[kMaxPoseObservations + i] = true;
    rays_[i] = PixelRay(calib.left, stereo[i].left_px);
  }
  Eigen::Matrix3d R = cam_T_model->R.cast<double>();
  Eigen::Vector3d t = cam_T_model->t_mm.cast<double>();
  if (!Solve(config, &R, &t)) return false;
  // Gate: errors (pixels, per observation) against a multiple of the median.
  auto errors = [&](double* e, size_t* n_e) {
    const size_t m = Residuals(R, t, residuals_);
    (void)m;
    size_t k = 0, j = 0;
    for (size_t i = 0; i < n_features_; ++i) {
      if (!active_[i]) continue;
      e[j++] = std::hypot(residuals_[k], residuals_[k + 1]) * features[i].sigma_px;
      k += 2;
    }
    for (size_t i = 0; i < n_stereo_; ++i) {
      if (!active_[kMaxPoseObservations + i]) continue;
      e[j++] = std::hypot(residuals_[k], residuals_[k + 1]);
      k += 2;
    }
    *n_e = j;
  };
  size_t n_e = 0;
  errors(shifted_, &n_e);
  if (n_e == 0) return false;
  double* sorted = shifted_ + n_e;
  std::copy(shifted_, shifted_ + n_e, sorted);
  std::nth_element(sorted, sorted + n_e / 2, sorted + n_e);
  const double gate = std::max(config.min_gate_px, config.gate_factor * sorted[n_e / 2]);
  size_t j = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    if (active_[i]) active_[i] = shifted_[j++] <= gate;
  }
  for (size_t i = 0; i < n_stereo_; ++i) {
    bool& a = active_[kMaxPoseObservations + i];
    if (a) a = shifted_[j++] <= gate;
  }
  if (!Solve(config, &R, &t)) return false;
  // Statistics over the kept observations.
  Residuals(R, t, residuals_);
  size_t k = 0;
  double fsum = 0, ssum = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    if (!active_[i]) continue;
    const double e = std::hypot(residuals_[k], residuals_[k + 1]) * features[i].sigma_px;
    fsum += e * e;
    ++stats->features_used;
    k += 2;
  }
  for (size_t i = 0; i < n_stereo_; ++i) {
    if (!active_[kMaxPoseObservations + i]) continue;
    const double e = std::hypot(residuals_[k], residuals_[k + 1]);
    ssum += e * e;
    ++stats->stereo_used;
    k += 2;
  }
  if (stats->features_used > 0) stats->feature_rms_px = std::sqrt(fsum / stats->features_used);
  if (stats->stereo_used > 0) stats->stereo_rms_px = std::sqrt(ssum / stats->stereo_used);
  cam_T_model->R = R.cast<float>();
  cam_T_model->t_mm = t.cast<float>();
  Orthonormalize(*cam_T_model);
  return true;
}

}  // namespace sh::texture
