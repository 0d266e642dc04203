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

bool TexturePoseRefiner::FeatureError(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                      double* e) const {
  const PoseFeatureObservation& o = features_[i];
  Eigen::Vector2d px;
  if (!ProjectToPixel(calib_->left, R * o.model_mm + t, &px)) return false;
  e[0] = px.x() - o.left_px.x();
  e[1] = px.y() - o.left_px.y();
  return true;
}

bool TexturePoseRefiner::StereoError(size_t i, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                     double* e) const {
  const StereoCalibration& c = *calib_;
  const PoseStereoObservation& o = stereo_[i];
  // The face plane in the camera: n_c . x = d + n_c . t.
  const Eigen::Vector3d n = R * o.plane_normal_model;
  const double d = o.plane_d_mm + n.dot(t);
  const double denom = n.dot(rays_[i]);
  if (std::fabs(denom) < 1e-9) return false;
  const double depth = d / denom;
  Eigen::Vector2d px;
  if (!(depth > 0) ||
      !ProjectToPixel(c.right, c.right_R_left * (depth * rays_[i]) + c.right_t_left_mm, &px))
    return false;
  e[0] = px.x() - o.right_px.x();
  e[1] = px.y() - o.right_px.y();
  return true;
}

size_t TexturePoseRefiner::Residuals(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                     double* out) const {
  size_t k = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    if (!active_[i]) continue;
    if (FeatureError(i, R, t, out + k)) {
      out[k] /= features_[i].sigma_px;
      out[k + 1] /= features_[i].sigma_px;
    } else {
      out[k] = out[k + 1] = kInvalidResidual;
    }
    k += 2;
  }
  // Unweighted: Solve scales the stereo block by 1 / stereo_sigma_px.
  for (size_t i = 0; i < n_stereo_; ++i) {
    if (!active_[kMaxPoseObservations + i]) continue;
    if (!StereoError(i, R, t, out + k)) out[k] = out[k + 1] = kInvalidResidual;
    k += 2;
  }
  return k;
}

void TexturePoseRefiner::Gate(const PoseRefineConfig& config, const Eigen::Matrix3d& R,
                              const Eigen::Vector3d& t) {
  // Pixel errors of every observation, kept or not, so that a better pose can readmit one.
  double* e = shifted_;
  size_t n = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    double r[2];
    e[n++] = FeatureError(i, R, t, r) ? std::hypot(r[0], r[1]) : kInvalidResidual;
  }
  for (size_t i = 0; i < n_stereo_; ++i) {
    double r[2];
    e[n++] = StereoError(i, R, t, r) ? std::hypot(r[0], r[1]) : kInvalidResidual;
  }
  // Median over the currently kept ones.
  double* kept = shifted_ + n;
  size_t m = 0;
  for (size_t i = 0; i < n_features_; ++i) {
    if (active_[i]) kept[m++] = e[i];
  }
  for (size_t i = 0; i < n_stereo_; ++i) {
    if (active_[kMaxPoseObservations + i]) kept[m++] = e[n_features_ + i];
  }
  if (m == 0) return;
  std::nth_element(kept, kept + m / 2, kept + m);
  const double gate = std::max(config.min_gate_px, config.gate_factor * kept[m / 2]);
  for (size_t i = 0; i < n_features_; ++i) active_[i] = e[i] <= gate;
  for (size_t i = 0; i < n_stereo_; ++i) {
    active_[kMaxPoseObservations + i] = e[n_features_ + i] <= gate;
  }
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
  // Gate against a multiple of the median error and solve again; twice, so that observations
  // a biased first pose pushed out come back once the outliers are gone.
  for (int round = 0; round < 2; ++round) {
    Gate(config, R, t);
    if (!Solve(config, &R, &t)) return false;
  }
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
