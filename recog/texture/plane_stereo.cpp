#include "recog/texture/plane_stereo.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "recog/texture/polygon.hpp"

namespace sh::texture {
namespace {

struct Candidate {
  float strength;
  int x, y;
};

// Right pixel of the point at inverse depth rho on the left ray.
bool RightPixelAt(const StereoCalibration& calib, const Eigen::Vector3d& ray, double rho,
                  Eigen::Vector2d* px) {
  const Eigen::Vector3d x_left = ray / rho;
  return ProjectToPixel(calib.right, calib.right_R_left * x_left + calib.right_t_left_mm, px);
}

}  // namespace

void SelectContourPoints(const ConstFloatView& min_eigenvalue, const Eigen::Vector2f* contour,
                         int n_contour, const PlaneStereoConfig& config,
                         Vector<Eigen::Vector2f>& points) {
  points.clear();
  if (n_contour < 3) return;
  float lo_x = 1e30f, lo_y = 1e30f, hi_x = -1e30f, hi_y = -1e30f;
  for (int i = 0; i < n_contour; ++i) {
    lo_x = std::min(lo_x, contour[i].x());
    lo_y = std::min(lo_y, contour[i].y());
    hi_x = std::max(hi_x, contour[i].x());
    hi_y = std::max(hi_y, contour[i].y());
  }
  const int r = config.nms_radius_px;
  const int edge = std::max(r, kMaxZnccRadiusPx + 2);
  const int x0 = std::max(edge, static_cast<int>(std::ceil(lo_x)));
  const int y0 = std::max(edge, static_cast<int>(std::ceil(lo_y)));
  const int x1 = std::min(min_eigenvalue.width - 1 - edge, static_cast<int>(std::floor(hi_x)));
  const int y1 = std::min(min_eigenvalue.height - 1 - edge, static_cast<int>(std::floor(hi_y)));
  // Strongest response inside, for the relative threshold.
  float peak = 0.0f;
  for (int y = y0; y <= y1; ++y) {
    const float* row = min_eigenvalue.row(y);
    for (int x = x0; x <= x1; ++x) peak = std::max(peak, row[x]);
  }
  const float threshold = std::max(config.min_strength, config.min_relative_strength * peak);
  const size_t capacity =
      std::min(points.capacity(), static_cast<size_t>(std::max(0, config.max_points)));
  // Min-heap of the strongest `capacity` maxima.
  Candidate heap[kMaxFaceStereoPoints];
  size_t n = 0;
  auto weaker_first = [](const Candidate& a, const Candidate& b) {
    return a.strength > b.strength;
  };
  for (int y = y0; y <= y1; ++y) {
    const float* row = min_eigenvalue.row(y);
    for (int x = x0; x <= x1; ++x) {
      const float v = row[x];
      if (!(v > threshold)) continue;
      if (n == capacity && capacity > 0 && v <= heap[0].strength) continue;
      bool is_max = true;
      for (int dy = -r; dy <= r && is_max; ++dy) {
        const float* nrow = min_eigenvalue.row(y + dy);
        for (int dx = -r; dx <= r; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const bool earlier = dy < 0 || (dy == 0 && dx < 0);
          if (earlier ? nrow[x + dx] >= v : nrow[x + dx] > v) {
            is_max = false;
            break;
          }
        }
      }
      if (!is_max) continue;
      const Eigen::Vector2f p(static_cast<float>(x), static_cast<float>(y));
      if (InsideDistance(contour, n_contour, p) < config.contour_margin_px) continue;
      if (n < capacity) {
        heap[n++] = {v, x, y};
        std::push_heap(heap, heap + n, weaker_first);
      } else if (capacity > 0) {
        std::pop_heap(heap, heap + n, weaker_first);
        heap[n - 1] = {v, x, y};
        std::push_heap(heap, heap + n, weaker_first);
      }
    }
  }
  std::sort_heap(heap, heap + n, weaker_first);
  for (size_t i = 0; i < n; ++i) {
    (void)points.push_back({static_cast<float>(heap[i].x), static_cast<float>(heap[i].y)});
  }
}

void PlaneStereoMatcher::Reset(const StereoCalibration* calib, ConstGrayView left,
                               ConstGrayView right) {
  calib_ = calib;
  left_ = left;
  right_ = right;
}

bool IntersectRayPlane(const Eigen::Vector3d& ray, const Plane3& plane, Eigen::Vector3d* x) {
  const double denom = plane.normal.dot(ray);
  if (std::fabs(denom) < 1e-9) return false;
  const double t = plane.d_mm / denom;
  if (!(t > 0)) return false;
  *x = t * ray;
  return true;
}

bool PlaneStereoMatcher::Match(const Eigen::Vector2f& left_px, const Plane3& prior,
                               const PlaneStereoConfig& config, StereoPoint* out) const {
  const StereoCalibration& calib = *calib_;
  const int r = std::clamp(config.window_radius_px, 1, kMaxZnccRadiusPx);
  const int lx = static_cast<int>(std::lround(left_px.x()));
  const int ly = static_cast<int>(std::lround(left_px.y()));
  if (lx < r || ly < r || lx >= left_.width - r || ly >= left_.height - r) return false;
  // Left window, zero mean.
  constexpr int kMaxWindow = (2 * kMaxZnccRadiusPx + 1) * (2 * kMaxZnccRadiusPx + 1);
  float lw[kMaxWindow];
  int n = 0;
  float lsum = 0;
  for (int dy = -r; dy <= r; ++dy) {
    const uint8_t* row = left_.row(ly + dy);
    for (int dx = -r; dx <= r; ++dx) {
      lw[n] = row[lx + dx];
      lsum += lw[n++];
    }
  }
  const float lmean = lsum / static_cast<float>(n);
  float lvar = 0;
  for (int i = 0; i < n; ++i) {
    lw[i] -= lmean;
    lvar += lw[i] * lw[i];
  }
  if (!(lvar > 1e-3f * static_cast<float>(n))) return false;  // flat window
  // Provisional 3-D point and the window's warp into the right image (plane-induced, by finite
  // differences over one pixel).
  const Eigen::Vector2d lp(lx, ly);
  const Eigen::Vector3d ray = PixelRay(calib.left, lp);
  Eigen::Vector3d x0;
  if (!IntersectRayPlane(ray, prior, &x0)) return false;
  Eigen::Vector2d c0, cx, cy;
  Eigen::Vector3d xx, xy;
  if (!IntersectRayPlane(PixelRay(calib.left, lp + Eigen::Vector2d(1, 0)), prior, &xx) ||
      !IntersectRayPlane(PixelRay(calib.left, lp + Eigen::Vector2d(0, 1)), prior, &xy))
    return false;
  const auto to_right = [&](const Eigen::Vector3d& x, Eigen::Vector2d* px) {
    return ProjectToPixel(calib.right, calib.right_R_left * x + calib.right_t_left_mm, px);
  };
  if (!to_right(x0, &c0) || !to_right(xx, &cx) || !to_right(xy, &cy)) return false;
  const Eigen::Vector2d jx = cx - c0, jy = cy - c0;
  // Search interval in inverse depth along the left ray; about one right pixel per step.
  const double rho0 = 1.0 / x0.norm();
  const double f = std::clamp(static_cast<double>(config.depth_search_fraction), 0.01, 0.9);
  const double rho_lo = rho0 * (1.0 - f), rho_hi = rho0 * (1.0 + f);
  Eigen::Vector2d p_lo, p_hi;
  if (!RightPixelAt(calib, ray, rho_lo, &p_lo) || !RightPixelAt(calib, ray, rho_hi, &p_hi))
    return false;
  const int steps =
      std::clamp(static_cast<int>(std::ceil((p_hi - p_lo).norm())) + 1, 5, kMaxEpipolarSamples);
  const double margin =
      r * (std::fabs(jx.x()) + std::fabs(jy.x()) + std::fabs(jx.y()) + std::fabs(jy.y())) + 2.0;
  const float jxx = static_cast<float>(jx.x()), jxy = static_cast<float>(jx.y());
  const float jyx = static_cast<float>(jy.x()), jyy = static_cast<float>(jy.y());
  // ZNCC of the warped window centred on sample s of the interval (-2 where it leaves the
  // image).
  auto zncc_at = [&](int s) {
    const double rho = rho_lo + (rho_hi - rho_lo) * s / (steps - 1);
    Eigen::Vector2d c;
    if (!RightPixelAt(calib, ray, rho, &c)) return -2.0f;
    if (c.x() < margin || c.y() < margin || c.x() > right_.width - 1 - margin ||
        c.y() > right_.height - 1 - margin)
      return -2.0f;
    float rw[kMaxWindow];
    float rsum = 0;
    int k = 0;
    for (int dy = -r; dy <= r; ++dy) {
      // Window row dy, stepping along the warped x direction.
      float qx = static_cast<float>(c.x()) + dy * jyx - r * jxx;
      float qy = static_cast<float>(c.y()) + dy * jyy - r * jxy;
      for (int dx = -r; dx <= r; ++dx, qx += jxx, qy += jxy) {
        rw[k] = SampleGrayInside(right_, qx, qy);
        rsum += rw[k++];
      }
    }
    const float rmean = rsum / static_cast<float>(n);
    float cross = 0, rvar = 0;
    for (int i = 0; i < n; ++i) {
      const float d = rw[i] - rmean;
      cross += lw[i] * d;
      rvar += d * d;
    }
    return rvar > 1e-6f ? cross / std::sqrt(lvar * rvar) : -1.0f;
  };
  // Coarse to fine: every second sample (the correlation peak of a window this wide spans
  // several pixels), then the odd neighbours of the best.
  float score[kMaxEpipolarSamples];
  int best = -1;
  for (int s = 0; s < steps; s += 2) {
    score[s] = zncc_at(s);
    if (best < 0 || score[s] > score[best]) best = s;
  }
  for (int s : {best - 1, best + 1}) {
    if (s < 0 || s >= steps) continue;
    score[s] = zncc_at(s);
  }
  for (int s : {best - 1, best + 1}) {
    if (s >= 0 && s < steps && score[s] > score[best]) best = s;
  }
  // Both neighbours of the best are now evaluated (an odd best lies between two even ones).
  if (best <= 0 || best >= steps - 1 || score[best] < config.min_zncc) return false;
  // Sub-sample peak by a parabola through the neighbours.
  const float a = score[best - 1], b = score[best], c = score[best + 1];
  const float denom = a - 2.0f * b + c;
  const double offset = denom < 0.0f ? std::clamp(0.5f * (a - c) / denom, -0.5f, 0.5f) : 0.0f;
  const double rho = rho_lo + (rho_hi - rho_lo) * (best + offset) / (steps - 1);
  Eigen::Vector2d rp;
  if (!RightPixelAt(calib, ray, rho, &rp)) return false;
  out->left_px = lp.cast<float>();
  out->right_px = rp.cast<float>();
  out->x_mm = (ray / rho).cast<float>();
  out->zncc = b;
  out->inlier = false;
  return true;
}

bool FitPlaneLeastSquares(const Eigen::Vector3d* points, int count, Plane3* plane) {
  if (count < 3) return false;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) c += points[i];
  c /= count;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i = 0; i < count; ++i) cov += (points[i] - c) * (points[i] - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success) return false;
  // The two larger eigenvalues must span a plane.
  if (!(eig.eigenvalues()(1) > 1e-9 * std::max(1.0, eig.eigenvalues()(2)))) return false;
  Eigen::Vector3d n = eig.eigenvectors().col(0);
  double d = n.dot(c);
  if (d > 0) {  // normal towards the camera (origin)
    n = -n;
    d = -d;
  }
  plane->normal = n;
  plane->d_mm = d;
  return true;
}

bool FitPlaneRansac(Vector<StereoPoint>& points, const PlaneStereoConfig& config, Plane3* plane,
                    PlaneFitStats* stats) {
  const int n = static_cast<int>(points.size());
  *stats = {};
  stats->points = n;
  for (StereoPoint& p : points) p.inlier = false;
  if (n < std::max(3, config.min_plane_points)) return false;
  Eigen::Vector3d xs[kMaxFaceStereoPoints];
  for (int i = 0; i < n; ++i) xs[i] = points[i].x_mm.cast<double>();
  const double tol = config.plane_tolerance_mm;
  auto count_inliers = [&](const Plane3& p) {
    int c = 0;
    for (int i = 0; i < n; ++i) c += std::fabs(p.normal.dot(xs[i]) - p.d_mm) <= tol ? 1 : 0;
    return c;
  };
  uint32_t state = 0x2545F491u;  // fixed seed: the same points give the same plane
  auto next = [&state]() {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  Plane3 best;
  int best_count = -1;
  for (int it = 0; it < config.ransac_iterations; ++it) {
    const int i = static_cast<int>(next() % static_cast<uint32_t>(n));
    const int j = static_cast<int>(next() % static_cast<uint32_t>(n));
    const int k = static_cast<int>(next() % static_cast<uint32_t>(n));
    if (i == j || j == k || i == k) continue;
    const Eigen::Vector3d normal = (xs[j] - xs[i]).cross(xs[k] - xs[i]);
    if (normal.norm() < 1e-6) continue;
    Plane3 p;
    p.normal = normal.normalized();
    p.d_mm = p.normal.dot(xs[i]);
    const int c = count_inliers(p);
    if (c > best_count) {
      best_count = c;
      best = p;
    }
  }
  if (best_count < 3) return false;
  // Least squares over the inliers, twice (the refit may gain or lose points at the margin).
  Eigen::Vector3d in[kMaxFaceStereoPoints];
  for (int pass = 0; pass < 2; ++pass) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
      if (std::fabs(best.normal.dot(xs[i]) - best.d_mm) <= tol) in[m++] = xs[i];
    }
    Plane3 refit;
    if (!FitPlaneLeastSquares(in, m, &refit)) return false;
    best = refit;
  }
  double sum = 0, sum2 = 0, worst = 0;
  int inliers = 0;
  for (int i = 0; i < n; ++i) {
    const double e = std::fabs(best.normal.dot(xs[i]) - best.d_mm);
    if (e > tol) continue;
    points[static_cast<size_t>(i)].inlier = true;
    ++inliers;
    sum += e;
    sum2 += e * e;
    worst = std::max(worst, e);
  }
  stats->inliers = inliers;
  if (inliers > 0) {
    stats->mean_abs_mm = sum / inliers;
    stats->rms_mm = std::sqrt(sum2 / inliers);
    stats->max_abs_mm = worst;
  }
  *plane = best;
  return inliers >= config.min_plane_points;
}

}  // namespace sh::texture
