#include "recog/shape/near_symmetry.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <limits>

#include "recog/geometry/rigid_transform.hpp"

namespace sh {

namespace {

// Largest distance of a moved corner to its nearest corner; with match != null, the nearest
// corner of each.
float WorstOffsetMm(const Model& model, const Eigen::Matrix3f& R, const Eigen::Vector3f& t_mm,
                    int* match) {
  float worst_mm = 0;
  for (int i = 0; i < model.n_corners; ++i) {
    const Eigen::Vector3f p = R * model.corner(i) + t_mm;
    float nearest_mm = std::numeric_limits<float>::max();
    for (int j = 0; j < model.n_corners; ++j) {
      const float d = (p - model.corner(j)).norm();
      if (d < nearest_mm) {
        nearest_mm = d;
        if (match != nullptr) match[i] = j;
      }
    }
    worst_mm = std::max(worst_mm, nearest_mm);
  }
  return worst_mm;
}

// The rigid motion (Kabsch) taking each corner onto its matched corner.
void FitMotion(const Model& model, const int* match, Eigen::Matrix3f* R, Eigen::Vector3f* t_mm) {
  Eigen::Vector3f pc = Eigen::Vector3f::Zero(), qc = Eigen::Vector3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) {
    pc += model.corner(i);
    qc += model.corner(match[i]);
  }
  pc /= static_cast<float>(model.n_corners);
  qc /= static_cast<float>(model.n_corners);
  Eigen::Matrix3f H = Eigen::Matrix3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) {
    H += (model.corner(i) - pc) * (model.corner(match[i]) - qc).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3f> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3f D = Eigen::Matrix3f::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0f : 1.0f;
  *R = svd.matrixV() * D * svd.matrixU().transpose();
  *t_mm = qc - *R * pc;
}

}  // namespace

NearSymmetries FindNearSymmetries(const Model& model, float max_offset_share) {
  NearSymmetries out;
  if (model.n_corners == 0) return out;
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) c += model.corner(i);
  c /= static_cast<float>(model.n_corners);
  Eigen::Matrix3f scatter = Eigen::Matrix3f::Zero();
  float radius_mm = 0;
  for (int i = 0; i < model.n_corners; ++i) {
    const Eigen::Vector3f d = model.corner(i) - c;
    scatter += d * d.transpose();
    radius_mm = std::max(radius_mm, d.norm());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eigen(scatter);
  int match[kMaxModelCorners];
  for (int a = 0; a < 3; ++a) {
    const Eigen::Vector3f axis = eigen.eigenvectors().col(a).normalized();
    // Half turn about the axis through the centroid: 2 a a^T - I, then fitted to the corners.
    Eigen::Matrix3f R = 2.0f * axis * axis.transpose() - Eigen::Matrix3f::Identity();
    Eigen::Vector3f t_mm = c - R * c;
    float worst_mm = WorstOffsetMm(model, R, t_mm, match);
    for (int round = 0; round < 5; ++round) {
      Eigen::Matrix3f R2;
      Eigen::Vector3f t2;
      FitMotion(model, match, &R2, &t2);
      int match2[kMaxModelCorners];
      const float worst2 = WorstOffsetMm(model, R2, t2, match2);
      if (!(worst2 < worst_mm)) break;
      R = R2, t_mm = t2, worst_mm = worst2;
      std::copy(match2, match2 + model.n_corners, match);
    }
    bool exact = worst_mm < 1e-3f * radius_mm;  // moves no corner off a corner
    for (int k = 0; k < model.n_symmetries && !exact; ++k) {
      exact = RotationAngleDeg(model.symmetry(k).transpose() * R) < 10.0f;
    }
    if (exact || worst_mm > max_offset_share * radius_mm) continue;
    bool seen = false;  // two axes fitted to the same motion
    for (int k = 0; k < out.n && !seen; ++k)
      seen = RotationAngleDeg(out.R[k].transpose() * R) < 10.0f;
    if (seen) continue;
    out.R[out.n] = R;
    out.t_mm[out.n] = t_mm;
    out.offset_mm[out.n] = worst_mm;
    ++out.n;
  }
  return out;
}

}  // namespace sh
