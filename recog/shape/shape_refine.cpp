#include "recog/shape/shape_refine.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace sh {
namespace {

constexpr float kMinDepthMm = 1.0f;
constexpr int kMinSolveSamples = 12;
constexpr float kTangentStepMm = 0.5f;
constexpr float kImageMarginPx = 1.0f;

using Vec6 = Eigen::Matrix<float, 6, 1>;
using Mat6 = Eigen::Matrix<float, 6, 6>;

// Rotation of a small rotation vector (exact, Rodrigues).
Eigen::Matrix3f Exp(const Eigen::Vector3f& w) {
  const float angle = w.norm();
  if (angle < 1e-12f) return Eigen::Matrix3f::Identity();
  return Eigen::AngleAxisf(angle, w / angle).toRotationMatrix();
}

Eigen::Matrix3f Skew(const Eigen::Vector3f& v) {
  Eigen::Matrix3f m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace

Status CheckShapeRefineConfig(const ShapeRefineConfig& c) {
  const bool ok = c.sample_step_px >= 0.5f && c.sample_step_px <= 50.0f &&
                  c.min_crease_angle_deg >= 0.0f && c.min_crease_angle_deg <= 180.0f &&
                  c.iterations >= 1 && c.iterations <= 100 && c.search_start_px >= 1.0f &&
                  c.search_start_px <= kMaxEdgeSearchPx && c.search_end_px >= 1.0f &&
                  c.search_end_px <= c.search_start_px && c.min_edge_contrast >= 0.0f &&
                  c.huber_px > 0.0f && c.confirm_px > 0.0f && c.converged_mm >= 0.0f &&
                  c.visibility_every >= 1 && c.min_start_share >= 0.0f && c.min_start_share <= 1.0f;
  if (!ok) {
    return Status::Error(StatusCode::kOutOfRange,
                         "shape refinement: settings out of range (step 0.5..50 px, iterations "
                         "1..100, search 1..%d px narrowing, positive tolerances)",
                         kMaxEdgeSearchPx);
  }
  return Status::Ok();
}

Status ShapeRefiner::Collect(const ViewCamera& view, const PosedModel& object,
                             const PosedModel* occluders, size_t n_occluders,
                             const ShapeRefineConfig& config, int camera) {
  SH_RETURN_IF_ERROR(ComputeVisibleEdges(view, object, occluders, n_occluders,
                                         config.sample_step_px, kMinDepthMm, &visible_));
  const Model& model = *object.model;
  const RigidTransform model_T_cam = (view.cam_T_left * object.cam_T_model).Inverse();
  const Eigen::Vector3f centre_model = model_T_cam.t_mm;
  const float cos_crease = std::cos(config.min_crease_angle_deg * 3.14159265f / 180.0f);
  int n = 0;
  // Samples beyond the capacity: every k-th is kept.
  int total = 0;
  for (int k = 0; k < visible_.n_edges; ++k) total += visible_.edges[k].n_samples;
  const int stride = total / kMaxRefineSamples + 1;
  int counter = 0;
  for (int k = 0; k < visible_.n_edges; ++k) {
    const VisibleEdge& ve = visible_.edges[k];
    const ModelEdge& edge = model.edges[ve.edge];
    const auto front = [&](int f) {
      return model.face_normal(f).dot(centre_model) - model.faces[f].offset_mm > 0.0f;
    };
    const bool f0 = front(edge.face0), f1 = front(edge.face1);
    const bool silhouette = f0 != f1;
    if (!silhouette &&
        model.face_normal(edge.face0).dot(model.face_normal(edge.face1)) > cos_crease) {
      continue;
    }
    const Eigen::Vector3f ea = model.corner(edge.a), eb = model.corner(edge.b);
    const Eigen::Vector3f along = (eb - ea).normalized();
    Eigen::Vector3f inward = Eigen::Vector3f::Zero();
    if (silhouette) {
      const ModelFace& face = model.faces[f0 ? edge.face0 : edge.face1];
      Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
      for (int v = 0; v < face.n_vertices; ++v) centroid += model.corner(face.vertices[v]);
      centroid /= static_cast<float>(face.n_vertices);
      const Eigen::Vector3f to_c = centroid - 0.5f * (ea + eb);
      inward = (to_c - to_c.dot(along) * along).normalized();
    }
    for (int i = 0; i < ve.n_samples; ++i) {
      if (!IsSampleVisible(ve, i) || (counter++ % stride) != 0) continue;
      if (n == kMaxRefineSamples) break;
      const Eigen::Vector3f x_cam = PointAtImageFraction(ve, SampleImageFraction(i, ve.n_samples));
      samples_[camera][n++] = {model_T_cam * x_cam, along, inward};
    }
  }
  n_samples_[camera] = n;
  return Status::Ok();
}

Status ShapeRefiner::Refine(const StereoCalibration& calib, const ShapeImages& images,
                            uint8_t colour, PosedModel* object, const PosedModel* occluders,
                            size_t n_occluders, const ShapeRefineConfig& config,
                            ShapeRefineResult* out) {
  if (object == nullptr || object->model == nullptr || out == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "shape refinement: null model or output");
  }
  SH_RETURN_IF_ERROR(CheckShapeRefineConfig(config));
  const CameraIntrinsics* intr[2] = {&calib.left, &calib.right};
  for (int cam = 0; cam < 2; ++cam) {
    if (images.rgb[cam].width != intr[cam]->width || images.rgb[cam].height != intr[cam]->height ||
        images.rgb[cam].data == nullptr) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "shape refinement: %s image is %dx%d but the calibration says %dx%d",
                           cam == 0 ? "left" : "right", images.rgb[cam].width,
                           images.rgb[cam].height, intr[cam]->width, intr[cam]->height);
    }
  }
  *out = ShapeRefineResult{};
  const Model& model = *object->model;
  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  const double max_r2[2] = {MaxImageRadius2(calib.left), MaxImageRadius2(calib.right)};
  float radius = 0;
  for (int i = 0; i < model.n_corners; ++i) radius = std::max(radius, model.corner(i).norm());

  // One pass over both images' samples at the current pose: normal equations of the samples
  // found within `range`, and the fit counts.
  auto pass = [&](int range, Mat6* H, Vec6* g, EdgeFit fit[2]) {
    H->setZero();
    g->setZero();
    for (int cam = 0; cam < 2; ++cam) {
      fit[cam] = EdgeFit{};
      const ViewCamera& view = views[cam];
      const RigidTransform cam_T_model = view.cam_T_left * object->cam_T_model;
      const CameraIntrinsics& ci = *intr[cam];
      const Eigen::Matrix3f& R_c = view.cam_T_left.R;
      for (int k = 0; k < n_samples_[cam]; ++k) {
        const Sample& smp = samples_[cam][k];
        const Eigen::Vector3f X = cam_T_model * smp.x_model;
        Eigen::Vector2f p, q;
        if (!ProjectInView(ci, max_r2[cam], X, &p) ||
            !ProjectInView(ci, max_r2[cam],
                           X + kTangentStepMm * cam_T_model.Rotate(smp.along_model), &q)) {
          continue;
        }
        if (p.x() < kImageMarginPx || p.y() < kImageMarginPx ||
            p.x() > ci.width - 1 - kImageMarginPx || p.y() > ci.height - 1 - kImageMarginPx) {
          continue;
        }
        const Eigen::Vector2f t = q - p;
        if (!(t.squaredNorm() > 1e-8f)) continue;
        Eigen::Vector2f n(-t.y(), t.x());
        n.normalize();
        const bool silhouette = smp.inward_model.squaredNorm() > 0.0f;
        if (silhouette) {
          Eigen::Vector2f r;
          if (!ProjectInView(ci, max_r2[cam],
                             X + kTangentStepMm * cam_T_model.Rotate(smp.inward_model), &r)) {
            continue;
          }
          if (n.dot(r - p) > 0.0f) n = -n;  // outward
        }
        ++fit[cam].samples;
        float s;
        if (!SearchEdge(images.rgb[cam], images.classes[cam], colour, silhouette, p, n, range,
                        config.min_edge_contrast, &s)) {
          continue;
        }
        ++fit[cam].found;
        if (std::fabs(s) <= config.confirm_px) ++fit[cam].confirmed;
        // d(n . p)/d(omega, v): rotation about the model origin in left-camera axes.
        const float z = X.z();
        Eigen::Matrix<float, 2, 3> Jp;
        Jp << ci.fx / z, 0, -ci.fx * X.x() / (z * z), 0, ci.fy / z, -ci.fy * X.y() / (z * z);
        // The sample relative to the model origin, in left-camera axes.
        const Eigen::Vector3f x_left_rel = object->cam_T_model.Rotate(smp.x_model);
        const Eigen::RowVector3f nJ = n.transpose() * Jp * R_c;
        Vec6 J;
        J.head<3>() = (nJ * -Skew(x_left_rel)).transpose();
        J.tail<3>() = nJ.transpose();
        const float a = std::fabs(s);
        const float w = a <= config.huber_px ? 1.0f : config.huber_px / a;
        *H += w * J * J.transpose();
        *g += w * J * s;
      }
    }
  };
  auto collect = [&]() -> Status {
    for (int cam = 0; cam < 2; ++cam) {
      SH_RETURN_IF_ERROR(Collect(views[cam], *object, occluders, n_occluders, config, cam));
    }
    return Status::Ok();
  };

  Mat6 H;
  Vec6 g;
  for (int it = 0; it < config.iterations; ++it) {
    if (it % config.visibility_every == 0) SH_RETURN_IF_ERROR(collect());
    const float f = config.iterations > 1 ? static_cast<float>(it) / (config.iterations - 1) : 1;
    const int range = static_cast<int>(
        std::lround(config.search_start_px + f * (config.search_end_px - config.search_start_px)));
    pass(range, &H, &g, out->fit);
    for (int cam = 0; cam < 2 && it == 0; ++cam) {
      const EdgeFit& f = out->fit[cam];
      if (static_cast<float>(f.found) < config.min_start_share * static_cast<float>(f.samples) ||
          (f.samples == 0 && config.min_start_share > 0.0f)) {
        return Status::Error(StatusCode::kNotFound,
                             "shape refinement: %s image shows %d of %d edge samples at the start",
                             cam == 0 ? "left" : "right", f.found, f.samples);
      }
    }
    const int used = out->fit[0].found + out->fit[1].found;
    if (used < kMinSolveSamples) {
      return Status::Error(StatusCode::kFailedPrecondition,
                           "shape refinement: %d edge samples found, %d needed", used,
                           kMinSolveSamples);
    }
    // Levenberg damping keeps directions the edges do not constrain (the can's axis) still.
    const float damping = 1e-4f * H.trace() / 6.0f + 1e-6f;
    const Vec6 delta = (H + damping * Mat6::Identity()).ldlt().solve(g);
    if (!delta.allFinite()) break;
    object->cam_T_model.R = Exp(delta.head<3>()) * object->cam_T_model.R;
    object->cam_T_model.t_mm += delta.tail<3>();
    Orthonormalize(object->cam_T_model);
    out->iterations = it + 1;
    if (delta.tail<3>().norm() + delta.head<3>().norm() * radius < config.converged_mm &&
        it + 1 >= config.iterations / 2) {
      out->converged = true;
      break;
    }
  }
  if (!config.final_fit) return Status::Ok();
  // Final fit at the pose reached, with fresh visibility and the narrowest search.
  SH_RETURN_IF_ERROR(collect());
  pass(static_cast<int>(std::lround(config.search_end_px)), &H, &g, out->fit);
  return Status::Ok();
}

}  // namespace sh
