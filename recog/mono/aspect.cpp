#include "recog/mono/aspect.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "recog/model/model_features.hpp"
#include "recog/verify/visible_edges.hpp"

namespace sh {
namespace {

// Focal length of the virtual camera for the hidden-line sampling. Only the sampling density
// depends on it; aspects are stored in normalised coordinates.
constexpr float kVirtualFocalPx = 1000.0f;

Eigen::Vector2f Normalised(const Eigen::Vector3f& x_cam) {
  return {x_cam.x() / x_cam.z(), x_cam.y() / x_cam.z()};
}

}  // namespace

CornerMask VisibleCorners2d(const Model& model, const VisibleEdgeSet& visible,
                            const Eigen::Vector2f* projected, float min_angle_deg) {
  // Directions of the visible edges leaving each corner (a corner of the reference shapes has
  // three edges; a fourth and more are ignored).
  Eigen::Vector2f dirs[kMaxModelCorners][4];
  int n_dirs[kMaxModelCorners] = {};
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    const ModelEdge& e = model.edges[ve.edge];
    const Eigen::Vector2f ab = projected[e.b] - projected[e.a];
    if (!(ab.norm() > 1e-9f)) continue;  // seen end-on
    if (ve.runs[0].first == 0 && n_dirs[e.a] < 4) dirs[e.a][n_dirs[e.a]++] = ab.normalized();
    if (ve.runs[ve.n_runs - 1].end == ve.n_samples && n_dirs[e.b] < 4) {
      dirs[e.b][n_dirs[e.b]++] = -ab.normalized();
    }
  }
  const float max_cos = std::cos(min_angle_deg * 3.14159265f / 180.0f);
  const ModelFeatures features = FeaturesOf(model);  // no tessellation vertices
  CornerMask mask;
  for (int i = 0; i < model.n_corners; ++i) {
    if (!features.corner(i)) continue;
    for (int p = 0; p < n_dirs[i]; ++p) {
      for (int q = p + 1; q < n_dirs[i]; ++q) {
        if (std::fabs(dirs[i][p].dot(dirs[i][q])) < max_cos) mask.set(static_cast<size_t>(i));
      }
    }
  }
  return mask;
}

Eigen::Vector3f ModelCentroid(const Model& model) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  for (int i = 0; i < model.n_corners; ++i) c += model.corner(i);
  return model.n_corners > 0 ? Eigen::Vector3f(c / static_cast<float>(model.n_corners)) : c;
}

float MeanCornerRadiusMm(const Model& model) {
  const Eigen::Vector3f c = ModelCentroid(model);
  float sum = 0;
  for (int i = 0; i < model.n_corners; ++i) sum += (model.corner(i) - c).norm();
  return model.n_corners > 0 ? sum / static_cast<float>(model.n_corners) : 0.0f;
}

RigidTransform AspectCamera(const Model& model, const Eigen::Vector3f& dir_model,
                            float distance_mm) {
  const Eigen::Vector3f d = dir_model.normalized();
  const Eigen::Vector3f z_cam = -d;  // the camera looks back at the centroid
  const Eigen::Vector3f ref =
      std::fabs(d.z()) < 0.99f ? Eigen::Vector3f(0, 0, 1) : Eigen::Vector3f(1, 0, 0);
  const Eigen::Vector3f x_cam = ref.cross(z_cam).normalized();
  const Eigen::Vector3f y_cam = z_cam.cross(x_cam);
  RigidTransform cam_T_model;
  cam_T_model.R.row(0) = x_cam;
  cam_T_model.R.row(1) = y_cam;
  cam_T_model.R.row(2) = z_cam;
  const Eigen::Vector3f centre_model = ModelCentroid(model) + distance_mm * d;
  cam_T_model.t_mm = -(cam_T_model.R * centre_model);
  return cam_T_model;
}

Status ComputeAspect(const Model& model, const Eigen::Vector3f& dir_model,
                     const AspectConfig& config, AspectView* out) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "aspect: no output");
  SH_RETURN_IF_ERROR(CheckModel(model));
  if (!(dir_model.norm() > 1e-6f)) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect: zero viewing direction");
  }
  if (!(config.distance_factor >= 2.0f && config.distance_factor <= 1000.0f) ||
      !(config.min_corner_angle_deg >= 0.0f && config.min_corner_angle_deg < 90.0f) ||
      !(config.min_segment_fraction >= 0.0f && config.min_segment_fraction < 2.0f) ||
      !(config.sample_fraction > 1e-4f && config.sample_fraction < 0.1f)) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect: configuration out of range");
  }
  const float radius_mm = MeanCornerRadiusMm(model);
  if (!(radius_mm > 0.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "aspect: model '%.31s' has no extent",
                         model.name);
  }
  AspectView& a = *out;
  a = AspectView{};
  a.dir_model = dir_model.normalized();
  a.distance_mm = config.distance_factor * radius_mm;
  a.cam_T_model = AspectCamera(model, a.dir_model, a.distance_mm);

  ViewCamera camera;
  camera.intrinsics.fx = camera.intrinsics.fy = kVirtualFocalPx;
  camera.intrinsics.width = camera.intrinsics.height = 1;  // not used by the hidden lines
  const PosedModel posed{&model, a.cam_T_model};
  // Sample spacing: a fraction of the projected mean radius (about f r / D pixels).
  const float step_px = config.sample_fraction * kVirtualFocalPx / config.distance_factor;
  VisibleEdgeSet visible;
  SH_RETURN_IF_ERROR(
      ComputeVisibleEdges(camera, posed, nullptr, 0, step_px, 0.01f * a.distance_mm, &visible));

  // Corners: ends of visible edges, kept where two visible edges leave at a proper angle.
  Eigen::Vector2f projected[kMaxModelCorners];
  std::fill(std::begin(projected), std::end(projected), Eigen::Vector2f::Zero());
  for (int i = 0; i < model.n_corners; ++i) {
    projected[i] = Normalised(a.cam_T_model * model.corner(i));
  }
  const CornerMask corners =
      VisibleCorners2d(model, visible, projected, config.min_corner_angle_deg);
  for (int i = 0; i < model.n_corners; ++i) {
    if (!corners.test(static_cast<size_t>(i))) continue;
    a.corners[a.n_corners].corner = static_cast<uint8_t>(i);
    a.corners[a.n_corners].xy = projected[i];
    ++a.n_corners;
    a.radius = std::max(a.radius, projected[i].norm());
  }

  // Segments: the visible pieces, long enough to be found by a line detector.
  float extent = 0;  // radius over all visible edge ends, for the length threshold
  for (int k = 0; k < visible.n_edges; ++k) {
    const ModelEdge& e = model.edges[visible.edges[k].edge];
    extent = std::max(extent, std::max(projected[e.a].norm(), projected[e.b].norm()));
  }
  const float min_length = config.min_segment_fraction * extent;
  // Of a part with curved surfaces, only what hashing uses (model_features.hpp): silhouettes
  // and rim chords of tessellated surfaces move with the view and are no lines a detector finds.
  const ModelFeatures features = FeaturesOf(model);
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    if (!features.line(ve.edge)) continue;
    const ModelEdge& e = model.edges[ve.edge];
    const Eigen::Vector2f pa = projected[e.a], pb = projected[e.b];
    for (int r = 0; r < ve.n_runs; ++r) {
      // Run [first, end) covers image fractions first / n .. end / n of the projected edge.
      const float s0 = static_cast<float>(ve.runs[r].first) / ve.n_samples;
      const float s1 = static_cast<float>(ve.runs[r].end) / ve.n_samples;
      const Eigen::Vector2f sa = pa + s0 * (pb - pa), sb = pa + s1 * (pb - pa);
      if (!((sb - sa).norm() >= min_length) || (sb - sa).norm() <= 0.0f) continue;
      if (a.n_segments == kMaxAspectSegments) {
        ++a.dropped_segments;
        continue;
      }
      a.segments[a.n_segments].edge = ve.edge;
      a.segments[a.n_segments].a = sa;
      a.segments[a.n_segments].b = sb;
      ++a.n_segments;
    }
  }
  return Status::Ok();
}

}  // namespace sh
