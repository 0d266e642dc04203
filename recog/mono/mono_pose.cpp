#include "recog/mono/mono_pose.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "recog/model/model_features.hpp"

namespace sh {
namespace {

// Distorted pixel of a point in the camera frame; false behind the camera.
bool Pixel(const CameraIntrinsics& cam, const Eigen::Vector3d& x, Eigen::Vector2d* px) {
  if (!(x.z() > 1e-6)) return false;
  const Eigen::Vector2d d = Distort(cam, x.head<2>() / x.z());
  *px = {cam.fx * d.x() + cam.cx, cam.fy * d.y() + cam.cy};
  return true;
}

// Weighted residuals of all matches for the pose cam_T_model (double precision); returns the
// count, or -1 when a matched point falls behind the camera.
int Residuals(const CameraIntrinsics& cam, const PoseMatches& m, const Eigen::Matrix3d& R,
              const Eigen::Vector3d& t, const FitConfig& c, double* r) {
  int n = 0;
  Eigen::Vector2d px;
  for (int i = 0; i < m.n_points; ++i) {
    if (!Pixel(cam, R * m.points[i].model.cast<double>() + t, &px)) return -1;
    r[n++] = (px.x() - m.points[i].px.x()) / c.sigma_corner_px;
    r[n++] = (px.y() - m.points[i].px.y()) / c.sigma_corner_px;
  }
  for (int i = 0; i < m.n_lines; ++i) {
    const PoseMatches::Line& l = m.lines[i];
    const Eigen::Vector2d normal = l.normal.cast<double>();
    for (const Eigen::Vector3f* end : {&l.a_model, &l.b_model}) {
      if (!Pixel(cam, R * end->cast<double>() + t, &px)) return -1;
      r[n++] = (normal.dot(px) - l.rho) / c.sigma_line_px;
    }
  }
  return n;
}

double HuberCost(const double* r, int n, double k) {
  double cost = 0;
  for (int i = 0; i < n; ++i) {
    const double a = std::fabs(r[i]);
    cost += a <= k ? 0.5 * a * a : k * (a - 0.5 * k);
  }
  return cost;
}

// Levenberg-damped Gauss-Newton with Huber weights and forward-difference Jacobians over N
// parameters; `pose(params, R, t)` maps parameters to a pose.
template <int N, typename PoseFn>
FitResult Fit(const CameraIntrinsics& cam, const PoseMatches& m, const FitConfig& c,
              const PoseFn& pose, FitScratch* scratch, Eigen::Matrix<double, N, 1>* params) {
  static_assert(N <= 6, "FitScratch holds six parameters");
  FitResult result;
  double* r = scratch->r;
  double* rp = scratch->r_trial;
  auto& J = scratch->J;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  pose(*params, &R, &t);
  int n = Residuals(cam, m, R, t, c, r);
  if (n < N) return result;
  double cost = HuberCost(r, n, c.huber);
  double lambda = 1e-3;
  for (int it = 0; it < c.iterations; ++it) {
    result.iterations = it + 1;
    for (int k = 0; k < N; ++k) {
      Eigen::Matrix<double, N, 1> p = *params;
      const double h = 1e-6 * std::max(1.0, std::fabs(p[k]));
      p[k] += h;
      pose(p, &R, &t);
      if (Residuals(cam, m, R, t, c, rp) != n) return result;
      for (int i = 0; i < n; ++i) J[i][k] = (rp[i] - r[i]) / h;
    }
    Eigen::Matrix<double, N, N> H = Eigen::Matrix<double, N, N>::Zero();
    Eigen::Matrix<double, N, 1> g = Eigen::Matrix<double, N, 1>::Zero();
    for (int i = 0; i < n; ++i) {
      const double a = std::fabs(r[i]);
      const double w = a <= c.huber ? 1.0 : c.huber / a;
      const Eigen::Map<const Eigen::Matrix<double, 1, N>> row(&J[i][0]);
      H.noalias() += w * row.transpose() * row;
      g.noalias() += w * r[i] * row.transpose();
    }
    bool improved = false;
    for (int attempt = 0; attempt < 6 && !improved; ++attempt) {
      Eigen::Matrix<double, N, N> A = H;
      for (int k = 0; k < N; ++k) A(k, k) += lambda * std::max(H(k, k), 1e-9);
      const Eigen::Matrix<double, N, 1> step = A.ldlt().solve(-g);
      if (!step.allFinite()) break;
      const Eigen::Matrix<double, N, 1> p = *params + step;
      pose(p, &R, &t);
      if (Residuals(cam, m, R, t, c, rp) == n) {
        const double new_cost = HuberCost(rp, n, c.huber);
        if (new_cost < cost) {
          *params = p;
          cost = new_cost;
          std::copy(rp, rp + n, r);
          lambda = std::max(1e-6, lambda * 0.3);
          improved = true;
          if (step.norm() < 1e-7) it = c.iterations;  // converged
          continue;
        }
      }
      lambda *= 10.0;
    }
    if (!improved) break;
  }
  // Unweighted RMS in pixels.
  double sum = 0;
  int k = 0;
  for (int i = 0; i < 2 * m.n_points; ++i, ++k)
    sum += r[i] * r[i] * c.sigma_corner_px * c.sigma_corner_px;
  for (int i = 2 * m.n_points; i < n; ++i, ++k)
    sum += r[i] * r[i] * c.sigma_line_px * c.sigma_line_px;
  result.rms_px = k > 0 ? static_cast<float>(std::sqrt(sum / k)) : 0.0f;
  return result;
}

}  // namespace

RigidTransform PoseFromHypothesis(const AspectRecord& aspect, const AspectBasis& basis,
                                  const Frame2d& scene_frame, float ideal_focal_px) {
  Frame2d aspect_frame;
  aspect_frame.origin = {basis.origin[0], basis.origin[1]};
  aspect_frame.axes = Eigen::Map<const Eigen::Matrix2f>(basis.axes);  // column-major
  // Scene ideal pixels per aspect normalised unit, and the image of the aspect's origin (the
  // projected centroid).
  const Eigen::Matrix2f A = scene_frame.axes * aspect_frame.axes.inverse();
  const Eigen::Vector2f centre_px = scene_frame.origin - A * aspect_frame.origin;
  Eigen::JacobiSVD<Eigen::Matrix2f> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix2f U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0.0f) U.col(1) = -U.col(1);
  const Eigen::Matrix2f rot2 = U * svd.matrixV().transpose();
  const float scale = std::sqrt(std::fabs(A.determinant())) / ideal_focal_px;

  const Eigen::Matrix3f virt_R =
      Eigen::Map<const Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(aspect.cam_T_model);
  const Eigen::Vector3f virt_t(aspect.cam_T_model[9], aspect.cam_T_model[10],
                               aspect.cam_T_model[11]);
  // The centroid sits on the virtual optical axis at distance_mm.
  const Eigen::Vector3f centroid_model =
      virt_R.transpose() * (Eigen::Vector3f(0, 0, aspect.distance_mm) - virt_t);
  Eigen::Matrix3f roll = Eigen::Matrix3f::Identity();
  roll.topLeftCorner<2, 2>() = rot2;
  const Eigen::Vector3f ray =
      Eigen::Vector3f(centre_px.x() / ideal_focal_px, centre_px.y() / ideal_focal_px, 1.0f)
          .normalized();
  RigidTransform cam_T_model;
  cam_T_model.R = RotationBetween(Eigen::Vector3f::UnitZ(), ray) * roll * virt_R;
  const float distance = aspect.distance_mm / std::max(scale, 1e-6f);
  cam_T_model.t_mm = distance * ray - cam_T_model.R * centroid_model;
  return cam_T_model;
}

void MatchFeatures(const CameraIntrinsics& cam, const Model& model,
                   const RigidTransform& cam_T_model, const VisibleEdgeSet& visible,
                   const PoseScene& scene, const MatchConfig& c, PoseMatches* out) {
  out->n_points = 0;
  out->n_lines = 0;
  out->corners_expected = 0;
  out->pieces_expected = 0;
  const double max_r2 = MaxImageRadius2(cam);
  Eigen::Vector2f projected[kMaxModelCorners];
  bool valid[kMaxModelCorners];
  for (int i = 0; i < model.n_corners; ++i) {
    valid[i] = ProjectInView(cam, max_r2, cam_T_model * model.corner(i), &projected[i]);
    if (!valid[i]) projected[i] = Eigen::Vector2f(1e9f, 1e9f);
  }
  const CornerMask corners = VisibleCorners2d(model, visible, projected, c.min_corner_angle_deg);
  const float corner_gate2 = c.corner_gate_px * c.corner_gate_px;
  for (int i = 0; i < model.n_corners; ++i) {
    if (!corners.test(static_cast<size_t>(i)) || !valid[i]) continue;
    if (!(projected[i].x() >= 0 && projected[i].y() >= 0 && projected[i].x() < cam.width &&
          projected[i].y() < cam.height)) {
      continue;
    }
    ++out->corners_expected;
    int best = -1;
    float best_d2 = corner_gate2;
    for (int k = 0; k < scene.n_corners; ++k) {
      if (scene.corner_active != nullptr && scene.corner_active[k] == 0) continue;
      const float d2 = (scene.corners[k].px - projected[i]).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = k;
    }
    if (best < 0 || out->n_points == kMaxMatchedCorners) continue;
    PoseMatches::Point& p = out->points[out->n_points++];
    p.model = model.corner(i);
    p.px = scene.corners[best].px;
    p.scene = static_cast<int16_t>(best);
    p.corner = static_cast<uint8_t>(i);
  }

  const float max_sin = std::sin(c.line_angle_deg * 3.14159265f / 180.0f);
  const ModelFeatures features = FeaturesOf(model);  // no silhouettes or chords of curves
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    if (!features.line(ve.edge)) continue;
    const ModelEdge& e = model.edges[ve.edge];
    const Eigen::Vector3f a_model = model.corner(e.a), ab_model = model.corner(e.b) - a_model;
    const float az = ve.a_cam_mm.z(), bz = ve.b_cam_mm.z();
    for (int r = 0; r < ve.n_runs; ++r) {
      // Image fractions of the run's ends -> fractions along the 3-D edge.
      float t3[2];
      const float s[2] = {static_cast<float>(ve.runs[r].first) / ve.n_samples,
                          static_cast<float>(ve.runs[r].end) / ve.n_samples};
      for (int q = 0; q < 2; ++q) t3[q] = s[q] * az / ((1.0f - s[q]) * bz + s[q] * az);
      const Eigen::Vector3f pa_model = a_model + t3[0] * ab_model;
      const Eigen::Vector3f pb_model = a_model + t3[1] * ab_model;
      Eigen::Vector2f pa, pb;
      if (!ProjectInView(cam, max_r2, cam_T_model * pa_model, &pa) ||
          !ProjectInView(cam, max_r2, cam_T_model * pb_model, &pb)) {
        continue;
      }
      const float length = (pb - pa).norm();
      if (!(length >= c.min_piece_px)) continue;
      ++out->pieces_expected;
      const Eigen::Vector2f dir = (pb - pa) / length;
      int best = -1;
      float best_cost = 2.0f * c.line_gate_px * c.line_gate_px;
      for (int l = 0; l < scene.n_lines; ++l) {
        if (scene.line_active != nullptr && scene.line_active[l] == 0) continue;
        const PoseLine& line = scene.lines[l];
        if (!(std::fabs(line.normal.dot(dir)) <= max_sin)) continue;
        const float da = line.normal.dot(pa) - line.rho, db = line.normal.dot(pb) - line.rho;
        if (!(std::fabs(da) <= c.line_gate_px && std::fabs(db) <= c.line_gate_px)) continue;
        const float ta = line.dir.dot(pa), tb = line.dir.dot(pb);
        const float lo = std::max(std::min(ta, tb), line.t0),
                    hi = std::min(std::max(ta, tb), line.t1);
        if (!(hi - lo >= c.min_overlap * length)) continue;
        const float cost = da * da + db * db;
        if (cost < best_cost) best_cost = cost, best = l;
      }
      if (best < 0 || out->n_lines == kMaxMatchedPieces) continue;
      PoseMatches::Line& m = out->lines[out->n_lines++];
      m.a_model = pa_model;
      m.b_model = pb_model;
      m.normal = scene.lines[best].normal;
      m.rho = scene.lines[best].rho;
      m.scene = static_cast<int16_t>(best);
      m.edge = ve.edge;
    }
  }
}

FitResult FitPose(const CameraIntrinsics& cam, const PoseMatches& matches, const FitConfig& config,
                  FitScratch* scratch, RigidTransform* cam_T_model) {
  // Rotation about the model's centroid (decouples rotation from translation): x_cam =
  // exp(w) R0 (x - c) + p, with p the centroid in the camera frame.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < matches.n_points; ++i) centroid += matches.points[i].model.cast<double>();
  for (int i = 0; i < matches.n_lines; ++i) {
    centroid += 0.5 * (matches.lines[i].a_model + matches.lines[i].b_model).cast<double>();
  }
  const int n_features = matches.n_points + matches.n_lines;
  if (n_features < 3) return {};
  centroid /= n_features;
  const Eigen::Matrix3d R0 = cam_T_model->R.cast<double>();
  const Eigen::Vector3d p0 = R0 * centroid + cam_T_model->t_mm.cast<double>();
  auto pose = [&](const Eigen::Matrix<double, 6, 1>& q, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
    const Eigen::Vector3d w = q.head<3>();
    const double angle = w.norm();
    const Eigen::Matrix3d dR = angle > 1e-12
                                   ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                                   : Eigen::Matrix3d::Identity();
    *R = dR * R0;
    *t = p0 + q.tail<3>() - *R * centroid;
  };
  Eigen::Matrix<double, 6, 1> q = Eigen::Matrix<double, 6, 1>::Zero();
  const FitResult r = Fit<6>(cam, matches, config, pose, scratch, &q);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  pose(q, &R, &t);
  cam_T_model->R = R.cast<float>();
  cam_T_model->t_mm = t.cast<float>();
  Orthonormalize(*cam_T_model);
  return r;
}

FitResult FitRestingPose(const CameraIntrinsics& cam, const PoseMatches& matches,
                         const TablePlane& table, const StableFaces& faces, const FitConfig& config,
                         FitScratch* scratch, RestingPose* pose) {
  const RestingPose start = *pose;
  // RestingTransform in double precision, so that the finite differences resolve.
  const Eigen::Matrix3d cam_R_table = table.cam_T_table.R.cast<double>();
  const Eigen::Vector3d cam_t_table = table.cam_T_table.t_mm.cast<double>();
  const Eigen::Matrix3d face_R = RestingRotation(faces.faces[start.face]).cast<double>();
  const double height = faces.faces[start.face].offset_mm;
  auto make = [&](const Eigen::Matrix<double, 3, 1>& q, Eigen::Matrix3d* R, Eigen::Vector3d* t) {
    const double heading = start.heading_rad + q[0];
    *R = cam_R_table * Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         face_R;
    *t = cam_R_table * Eigen::Vector3d(start.x_mm + q[1], start.y_mm + q[2], height) + cam_t_table;
  };
  Eigen::Matrix<double, 3, 1> q = Eigen::Matrix<double, 3, 1>::Zero();
  const FitResult r = Fit<3>(cam, matches, config, make, scratch, &q);
  pose->heading_rad = static_cast<float>(start.heading_rad + q[0]);
  pose->x_mm = static_cast<float>(start.x_mm + q[1]);
  pose->y_mm = static_cast<float>(start.y_mm + q[2]);
  return r;
}

}  // namespace sh
