#include "recog/texture/absolute_orientation.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

namespace sh::texture {

bool AbsoluteOrientation(const Eigen::Vector3d* a, const Eigen::Vector3d* b, const double* weights,
                         int count, RigidTransform* b_T_a) {
  if (count < 3) return false;
  double wsum = 0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) {
    const double w = weights ? weights[i] : 1.0;
    wsum += w;
    ca += w * a[i];
    cb += w * b[i];
  }
  if (!(wsum > 0)) return false;
  ca /= wsum;
  cb /= wsum;
  // Cross-covariance S = sum w (a - ca)(b - cb)^T.
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  double spread = 0;
  for (int i = 0; i < count; ++i) {
    const double w = weights ? weights[i] : 1.0;
    S += w * (a[i] - ca) * (b[i] - cb).transpose();
    spread += w * (a[i] - ca).squaredNorm();
  }
  const double sxx = S(0, 0), sxy = S(0, 1), sxz = S(0, 2);
  const double syx = S(1, 0), syy = S(1, 1), syz = S(1, 2);
  const double szx = S(2, 0), szy = S(2, 1), szz = S(2, 2);
  Eigen::Matrix4d N;
  N << sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,  //
      syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,   //
      szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,  //
      sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::Vector4d& ev = eig.eigenvalues();
  // Collinear points: the two largest eigenvalues coincide (rotation about the line free).
  if (!(spread > 0) || ev(3) - ev(2) < 1e-9 * spread) return false;
  const Eigen::Vector4d q = eig.eigenvectors().col(3);  // (w, x, y, z), largest eigenvalue
  const Eigen::Quaterniond quat(q(0), q(1), q(2), q(3));
  const Eigen::Matrix3d R = quat.normalized().toRotationMatrix();
  const Eigen::Vector3d t = cb - R * ca;
  if (!R.allFinite() || !t.allFinite()) return false;
  b_T_a->R = R.cast<float>();
  b_T_a->t_mm = t.cast<float>();
  return true;
}

}  // namespace sh::texture
