#include "recog/texture/planar_fit.hpp"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <cmath>

namespace sh::texture {
namespace {

// A range of matches for range-for.
struct Span {
  const PlanarMatch* first;
  size_t size;
  Span(const PlanarMatch* m, size_t n) : first(m), size(n) {}
  const PlanarMatch* begin() const { return first; }
  const PlanarMatch* end() const { return first + size; }
};

// Centring and scaling of both point sets (Hartley): mean at 0, mean distance sqrt(2).
struct Normaliser {
  double fa = 1, ca = 0, cb = 0;  // face: (a - ca) * fa
  double fx = 1, cx = 0, cy = 0;  // image: (x - cx) * fx
};

Normaliser MakeNormaliser(const PlanarMatch* m, size_t size) {
  Normaliser n;
  const double count = static_cast<double>(size);
  for (const PlanarMatch& p : Span(m, size)) {
    n.ca += p.a_mm;
    n.cb += p.b_mm;
    n.cx += p.x_px;
    n.cy += p.y_px;
  }
  n.ca /= count;
  n.cb /= count;
  n.cx /= count;
  n.cy /= count;
  double da = 0, dx = 0;
  for (const PlanarMatch& p : Span(m, size)) {
    da += std::hypot(p.a_mm - n.ca, p.b_mm - n.cb);
    dx += std::hypot(p.x_px - n.cx, p.y_px - n.cy);
  }
  n.fa = da > 0 ? std::sqrt(2.0) * count / da : 1.0;
  n.fx = dx > 0 ? std::sqrt(2.0) * count / dx : 1.0;
  return n;
}

// Keeps the matches whose error (affine) is at most factor * mean; returns the mean.
double DropAffineOutliers(Vector<PlanarMatch>& m, const Eigen::Matrix<double, 2, 3>& A,
                          float factor) {
  double errors_sum = 0;
  for (const PlanarMatch& p : m) {
    const Eigen::Vector2d e =
        A * Eigen::Vector3d(p.a_mm, p.b_mm, 1.0) - Eigen::Vector2d(p.x_px, p.y_px);
    errors_sum += e.norm();
  }
  const double mean = errors_sum / static_cast<double>(m.size());
  for (size_t i = m.size(); i-- > 0;) {
    const PlanarMatch& p = m[i];
    const Eigen::Vector2d e =
        A * Eigen::Vector3d(p.a_mm, p.b_mm, 1.0) - Eigen::Vector2d(p.x_px, p.y_px);
    if (e.norm() > factor * mean) m.swap_remove(i);
  }
  return mean;
}

}  // namespace

bool FitAffine(const Vector<PlanarMatch>& matches, Eigen::Matrix<double, 2, 3>* affine) {
  return FitAffine(matches.data(), matches.size(), affine);
}

bool FitAffine(const PlanarMatch* matches, size_t count, Eigen::Matrix<double, 2, 3>* affine) {
  if (count < 3) return false;
  const Normaliser n = MakeNormaliser(matches, count);
  // Both rows share the normal matrix of (a, b, 1).
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
  for (const PlanarMatch& p : Span(matches, count)) {
    const Eigen::Vector3d a((p.a_mm - n.ca) * n.fa, (p.b_mm - n.cb) * n.fa, 1.0);
    ata += a * a.transpose();
    atb += a * Eigen::RowVector2d((p.x_px - n.cx) * n.fx, (p.y_px - n.cy) * n.fx);
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (lu.rank() < 3) return false;
  const Eigen::Matrix<double, 3, 2> c = lu.solve(atb);
  // Undo the normalisation: x = cx + (c^T (fa (a - ca), fa (b - cb), 1)) / fx.
  Eigen::Matrix3d Tf;
  Tf << n.fa, 0, -n.fa * n.ca, 0, n.fa, -n.fa * n.cb, 0, 0, 1;
  Eigen::Matrix3d Ti;
  Ti << 1.0 / n.fx, 0, n.cx, 0, 1.0 / n.fx, n.cy, 0, 0, 1;
  Eigen::Matrix3d An = Eigen::Matrix3d::Identity();
  An.topRows<2>() = c.transpose();
  const Eigen::Matrix3d full = Ti * An * Tf;
  *affine = full.topRows<2>();
  return affine->allFinite();
}

bool FitHomography(const Vector<PlanarMatch>& matches, Eigen::Matrix3d* image_H_face) {
  if (matches.size() < 4) return false;
  const Normaliser n = MakeNormaliser(matches.data(), matches.size());
  Eigen::Matrix<double, 8, 8> ata = Eigen::Matrix<double, 8, 8>::Zero();
  Eigen::Matrix<double, 8, 1> atb = Eigen::Matrix<double, 8, 1>::Zero();
  for (const PlanarMatch& p : matches) {
    const double u = (p.a_mm - n.ca) * n.fa, v = (p.b_mm - n.cb) * n.fa;
    const double x = (p.x_px - n.cx) * n.fx, y = (p.y_px - n.cy) * n.fx;
    Eigen::Matrix<double, 8, 1> r1, r2;
    r1 << u, v, 1, 0, 0, 0, -u * x, -v * x;
    r2 << 0, 0, 0, u, v, 1, -u * y, -v * y;
    ata += r1 * r1.transpose() + r2 * r2.transpose();
    atb += r1 * x + r2 * y;
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(ata);
  if (lu.rank() < 8) return false;
  const Eigen::Matrix<double, 8, 1> h = lu.solve(atb);
  Eigen::Matrix3d Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  Eigen::Matrix3d Tf;
  Tf << n.fa, 0, -n.fa * n.ca, 0, n.fa, -n.fa * n.cb, 0, 0, 1;
  Eigen::Matrix3d Ti;
  Ti << 1.0 / n.fx, 0, n.cx, 0, 1.0 / n.fx, n.cy, 0, 0, 1;
  Eigen::Matrix3d H = Ti * Hn * Tf;
  if (!H.allFinite() || std::fabs(H(2, 2)) < 1e-300) return false;
  *image_H_face = H / H(2, 2);
  return true;
}

Eigen::Vector2d ApplyHomography(const Eigen::Matrix3d& H, double a, double b) {
  const Eigen::Vector3d p = H * Eigen::Vector3d(a, b, 1.0);
  return p.head<2>() / p.z();
}

bool KeepAffineConsensus(Vector<PlanarMatch>& matches, const PlanarFitConfig& config) {
  const size_t n = matches.size();
  if (n < 3 || config.consensus_samples < 1) return false;
  const double tolerance2 = static_cast<double>(config.consensus_px) * config.consensus_px;
  const auto triples =
      static_cast<double>(n) * static_cast<double>(n - 1) * static_cast<double>(n - 2) / 6.0;
  const bool every = triples <= config.consensus_samples;
  const int samples = every ? static_cast<int>(triples) : config.consensus_samples;
  uint32_t state = 0x9e3779b9u;  // fixed seed: the same matches give the same set
  auto next = [&state](size_t bound) {
    state = state * 1664525u + 1013904223u;
    return static_cast<size_t>((static_cast<uint64_t>(state) * bound) >> 32);
  };
  size_t i = 0, j = 1, k = 2;  // the current triple when every triple is tried
  Eigen::Matrix<double, 2, 3> best_A;
  size_t best_count = 0;
  for (int s = 0; s < samples; ++s) {
    if (every) {
      if (s > 0 && ++k == n) {
        if (++j == n - 1) j = ++i + 1;
        k = j + 1;
      }
    } else {
      i = next(n);
      j = next(n - 1);
      j += j >= i ? 1 : 0;
      k = next(n - 2);
      k += k >= std::min(i, j) ? 1 : 0;
      k += k >= std::max(i, j) ? 1 : 0;
    }
    const PlanarMatch& p0 = matches[i];
    const PlanarMatch& p1 = matches[j];
    const PlanarMatch& p2 = matches[k];
    // Collinear or coincident on the face (under 1 mm^2 spanned): no map.
    const double spanned = (static_cast<double>(p1.a_mm) - p0.a_mm) * (p2.b_mm - p0.b_mm) -
                           (static_cast<double>(p2.a_mm) - p0.a_mm) * (p1.b_mm - p0.b_mm);
    if (std::fabs(spanned) < 1.0) continue;
    // The affine map through the three: rows (a, b, 1) -> (x, y).
    Eigen::Matrix3d M;
    Eigen::Matrix<double, 3, 2> X;
    M << p0.a_mm, p0.b_mm, 1.0, p1.a_mm, p1.b_mm, 1.0, p2.a_mm, p2.b_mm, 1.0;
    X << p0.x_px, p0.y_px, p1.x_px, p1.y_px, p2.x_px, p2.y_px;
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(M);
    const Eigen::Matrix<double, 2, 3> A = lu.solve(X).transpose();
    size_t count = 0;
    for (const PlanarMatch& p : matches) {
      const Eigen::Vector2d e =
          A * Eigen::Vector3d(p.a_mm, p.b_mm, 1.0) - Eigen::Vector2d(p.x_px, p.y_px);
      count += e.squaredNorm() <= tolerance2 ? 1 : 0;
    }
    if (count > best_count) {
      best_count = count;
      best_A = A;
    }
  }
  if (best_count == 0) return false;
  for (size_t m = matches.size(); m-- > 0;) {
    const PlanarMatch& p = matches[m];
    const Eigen::Vector2d e =
        best_A * Eigen::Vector3d(p.a_mm, p.b_mm, 1.0) - Eigen::Vector2d(p.x_px, p.y_px);
    if (e.squaredNorm() > tolerance2) matches.swap_remove(m);
  }
  return true;
}

bool LimitPerspective(const float (*corners_ab_mm)[2], int n_corners,
                      const Vector<PlanarMatch>& matches, double min_depth_mm, PlanarFit* fit) {
  if (matches.empty() || !(min_depth_mm > 0)) return false;
  const Eigen::Matrix3d& H = fit->image_H_face;
  double ca = 0, cb = 0;
  for (const PlanarMatch& m : matches) {
    ca += m.a_mm;
    cb += m.b_mm;
  }
  ca /= static_cast<double>(matches.size());
  cb /= static_cast<double>(matches.size());
  const double w0 = H(2, 0) * ca + H(2, 1) * cb + H(2, 2);
  bool plausible = w0 > 0;
  for (int k = 0; k < n_corners && plausible; ++k) {
    const double a = corners_ab_mm[k][0], b = corners_ab_mm[k][1];
    const double w = H(2, 0) * a + H(2, 1) * b + H(2, 2);
    plausible = std::fabs(w / w0 - 1.0) <= std::hypot(a - ca, b - cb) / min_depth_mm;
  }
  if (plausible) return false;
  Eigen::Matrix<double, 2, 3> affine;
  if (!FitAffine(matches, &affine)) return false;
  fit->image_H_face.setIdentity();
  fit->image_H_face.topRows<2>() = affine;
  return true;
}

PlanarFit FitFacePlane(Vector<PlanarMatch>& matches, const PlanarFitConfig& config) {
  PlanarFit fit;
  for (int it = 0; it < config.affine_iterations; ++it) {
    Eigen::Matrix<double, 2, 3> A;
    if (!FitAffine(matches, &A)) return fit;
    DropAffineOutliers(matches, A, config.outlier_factor);
  }
  if (!FitHomography(matches, &fit.image_H_face)) return fit;
  double sum = 0;
  for (const PlanarMatch& p : matches) {
    sum += (ApplyHomography(fit.image_H_face, p.a_mm, p.b_mm) - Eigen::Vector2d(p.x_px, p.y_px))
               .norm();
  }
  fit.matches = static_cast<int>(matches.size());
  fit.mean_error_px = matches.empty() ? 0.0 : sum / static_cast<double>(matches.size());
  fit.accepted = fit.matches >= config.min_matches && fit.mean_error_px < config.max_mean_error_px;
  return fit;
}

double MaxImageScale(const Eigen::Matrix3d& H, double a, double b) {
  const Eigen::Vector3d p = H * Eigen::Vector3d(a, b, 1.0);
  const double w = p.z();
  if (std::fabs(w) < 1e-300) return 0.0;
  const double x = p.x() / w, y = p.y() / w;
  Eigen::Matrix2d J;
  J << H(0, 0) - x * H(2, 0), H(0, 1) - x * H(2, 1), H(1, 0) - y * H(2, 0), H(1, 1) - y * H(2, 1);
  J /= w;
  return Eigen::JacobiSVD<Eigen::Matrix2d>(J).singularValues()(0);
}

bool PoseFromHomography(const Eigen::Matrix3d& image_H_face, double fx, double fy, double cx,
                        double cy, RigidTransform* cam_T_face) {
  Eigen::Matrix3d Kinv;
  Kinv << 1.0 / fx, 0, -cx / fx, 0, 1.0 / fy, -cy / fy, 0, 0, 1;
  Eigen::Matrix3d M = Kinv * image_H_face;  // ~ [r1 r2 t]
  const double n1 = M.col(0).norm(), n2 = M.col(1).norm();
  if (!(n1 > 0 && n2 > 0)) return false;
  double lambda = 2.0 / (n1 + n2);
  if (M(2, 2) * lambda < 0) lambda = -lambda;  // the face origin in front of the camera
  M *= lambda;
  Eigen::Matrix3d R0;
  R0.col(0) = M.col(0);
  R0.col(1) = M.col(1);
  R0.col(2) = M.col(0).cross(M.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R0, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1.0;
    R = U * svd.matrixV().transpose();
  }
  const Eigen::Vector3d t = M.col(2);
  if (!R.allFinite() || !t.allFinite() || !(t.z() > 0)) return false;
  cam_T_face->R = R.cast<float>();
  cam_T_face->t_mm = t.cast<float>();
  return true;
}

}  // namespace sh::texture
