#include "recog/verify/visible_edges.hpp"

#include <cmath>

namespace sh {
namespace {

static_assert(kMaxModelFaces <= 64, "front-face sets are 64-bit masks");
static_assert(kMaxSamplesPerEdge <= 0xffff, "sample indices are uint16_t");
static_assert(kMaxOccluders <= 32, "relevant occluders are a 32-bit mask");

// Faces whose outward side contains the point c (model frame): the faces c can see.
uint64_t FrontFaceMask(const Model& m, const Eigen::Vector3d& c) {
  uint64_t mask = 0;
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    const double side =
        face.normal[0] * c.x() + face.normal[1] * c.y() + face.normal[2] * c.z() - face.offset_mm;
    if (side > 0.0) mask |= uint64_t{1} << f;
  }
  return mask;
}

// Crossing-number test of point h (on the face's plane) against the face polygon, in the plane
// of the two coordinate axes that the normal is least aligned with. Correct for non-convex
// simple polygons such as the star's 10-gons.
bool PointInFace(const Model& m, const ModelFace& face, const double h[3]) {
  const double ax = std::fabs(face.normal[0]), ay = std::fabs(face.normal[1]),
               az = std::fabs(face.normal[2]);
  const int drop = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
  const int u = drop == 0 ? 1 : 0;
  const int v = drop == 2 ? 1 : 2;
  const double pu = h[u], pv = h[v];
  bool inside = false;
  int j = face.n_vertices - 1;
  for (int k = 0; k < face.n_vertices; ++k) {
    const float* pk = m.corners_mm[face.vertices[k]];
    const float* pj = m.corners_mm[face.vertices[j]];
    const double ku = pk[u], kv = pk[v], ju = pj[u], jv = pj[v];
    if ((kv > pv) != (jv > pv)) {
      const double cross_u = ku + (ju - ku) * (pv - kv) / (jv - kv);
      if (pu < cross_u) inside = !inside;
    }
    j = k;
  }
  return inside;
}

// True if the segment from the camera centre c to the point x (both in the model's frame) meets
// one of the faces in `mask` more than kOcclusionToleranceMm before x. Only faces that face c
// can be entered by the ray; back faces are where it leaves the solid, after a front face.
bool RayBlocked(const Model& m, uint64_t mask, const Eigen::Vector3d& c, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - c;
  const double length = d.norm();
  if (!(length > kOcclusionToleranceMm)) return false;
  const double t_max = 1.0 - kOcclusionToleranceMm / length;
  for (int f = 0; mask != 0; ++f, mask >>= 1) {
    if (!(mask & 1u)) continue;
    const ModelFace& face = m.faces[f];
    const double nd = face.normal[0] * d.x() + face.normal[1] * d.y() + face.normal[2] * d.z();
    if (!(nd < 0.0)) continue;  // parallel to the face or moving away from its front side
    const double nc = face.normal[0] * c.x() + face.normal[1] * c.y() + face.normal[2] * c.z();
    const double t = (face.offset_mm - nc) / nd;  // > 0 since c is in front of the face
    if (!(t < t_max)) continue;
    const double h[3] = {c.x() + t * d.x(), c.y() + t * d.y(), c.z() + t * d.z()};
    if (PointInFace(m, face, h)) return true;
  }
  return false;
}

// Whether every corner lies behind or on every face's plane (within kConvexToleranceMm): a
// convex solid. Such a model hides none of its own edges that have a face turned to the camera:
// the ray to a point of that face comes from the outer side of the face's plane, behind which
// the whole solid lies, so it meets the solid nowhere before the point. Self-occlusion is then
// not tested (the test would find nothing: the same samples, without its cost).
constexpr double kConvexToleranceMm = 1e-3;

bool IsConvex(const Model& m) {
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    for (int k = 0; k < m.n_corners; ++k) {
      const float* p = m.corners_mm[k];
      const double side = double{face.normal[0]} * p[0] + double{face.normal[1]} * p[1] +
                          double{face.normal[2]} * p[2] - face.offset_mm;
      if (side > kConvexToleranceMm) return false;
    }
  }
  return true;
}

// Extent of something as seen from the camera: the box of its rays in normalised image
// coordinates (x/z, y/z) and its nearest depth. A face can hide part of an edge only if their
// boxes overlap and the face comes nearer than the edge's far end (along one ray, nearer means
// smaller z).
struct RayBox {
  float x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, z0 = INFINITY;
  void Add(const Eigen::Vector3f& p_cam) {
    const float x = p_cam.x() / p_cam.z(), y = p_cam.y() / p_cam.z();
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
    z0 = std::min(z0, p_cam.z());
  }
  // Everything: for things reaching behind the camera plane, where the box means nothing.
  static RayBox All() { return {-INFINITY, -INFINITY, INFINITY, INFINITY, -INFINITY}; }
  bool MayHide(const RayBox& edge, float edge_far_z) const {
    constexpr float kMargin = 1e-4f;  // about 0.1 px at f = 1000 px
    return x0 <= edge.x1 + kMargin && edge.x0 <= x1 + kMargin && y0 <= edge.y1 + kMargin &&
           edge.y0 <= y1 + kMargin && z0 < edge_far_z;
  }
};

// An accepted object as seen from the camera being processed.
struct Occluder {
  const Model* model = nullptr;
  Eigen::Matrix3d occ_R_cam;
  Eigen::Vector3d occ_t_cam;  // also the camera centre in the occluder's frame
  uint64_t front_mask = 0;
  Eigen::Vector3d centre_cam;  // bounding sphere, camera frame
  double radius2 = 0;
  RayBox box;
};

// Squared distance from point s to the segment 0..x.
double SegmentDistance2(const Eigen::Vector3d& x, const Eigen::Vector3d& s) {
  const double xx = x.squaredNorm();
  const double u = xx > 0 ? std::max(0.0, std::min(1.0, x.dot(s) / xx)) : 0.0;
  return (u * x - s).squaredNorm();
}

bool BlockedByOccluders(const Occluder* occ, size_t n, uint32_t relevant,
                        const Eigen::Vector3d& x_cam) {
  for (size_t i = 0; i < n; ++i) {
    if (!(relevant & (1u << i))) continue;
    if (SegmentDistance2(x_cam, occ[i].centre_cam) > occ[i].radius2) continue;
    const Eigen::Vector3d x_occ = occ[i].occ_R_cam * x_cam + occ[i].occ_t_cam;
    if (RayBlocked(*occ[i].model, occ[i].front_mask, occ[i].occ_t_cam, x_occ)) return true;
  }
  return false;
}

// The arguments of ComputeVisibleEdges past the null checks, and the model's depth (its
// corners must lie at least min_depth_mm in front of the camera).
Status CheckVisibleEdgeInputs(const ViewCamera& camera, const PosedModel& object,
                              const PosedModel* occluders, size_t n_occluders, float sample_step_px,
                              float min_depth_mm) {
  if (!(sample_step_px >= 0.05f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "visible edges: sample step %g px must be >= 0.05", sample_step_px);
  }
  if (n_occluders > kMaxOccluders || (n_occluders > 0 && occluders == nullptr)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "visible edges: %zu occluders (capacity %zu)", n_occluders, kMaxOccluders);
  }
  const Model& m = *object.model;
  SH_RETURN_IF_ERROR(CheckModel(m));
  const float min_z = MinCornerDepthMm(camera, object);
  if (!(min_z >= min_depth_mm)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "visible edges: model '%.31s' reaches depth %.1f mm, behind the camera "
                         "(minimum %.1f mm)",
                         m.name, min_z, min_depth_mm);
  }
  return Status::Ok();
}

// Occluder `index` as this camera sees it: its pose, the faces it turns to the camera, its
// bounding sphere and its ray box.
Status PlaceOccluder(const ViewCamera& camera, const PosedModel& occluder, size_t index,
                     Occluder* occ) {
  const Model* om = occluder.model;
  if (om == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "visible edges: occluder %zu has no model",
                         index);
  }
  SH_RETURN_IF_ERROR(CheckModel(*om));
  const RigidTransform cam_T_occ = camera.cam_T_left * occluder.cam_T_model;
  const RigidTransform occ_T_cam = cam_T_occ.Inverse();
  occ->model = om;
  occ->occ_R_cam = occ_T_cam.R.cast<double>();
  occ->occ_t_cam = occ_T_cam.t_mm.cast<double>();
  occ->front_mask = FrontFaceMask(*om, occ->occ_t_cam);
  Eigen::Vector3d centre_model = Eigen::Vector3d::Zero();
  for (int k = 0; k < om->n_corners; ++k) centre_model += om->corner(k).cast<double>();
  if (om->n_corners > 0) centre_model /= om->n_corners;
  double r2 = 0;
  for (int k = 0; k < om->n_corners; ++k) {
    r2 = std::max(r2, (om->corner(k).cast<double>() - centre_model).squaredNorm());
  }
  occ->centre_cam = cam_T_occ.R.cast<double>() * centre_model + cam_T_occ.t_mm.cast<double>();
  const double radius = std::sqrt(r2) + kOcclusionToleranceMm;
  occ->radius2 = radius * radius;
  for (int k = 0; k < om->n_corners; ++k) {
    const Eigen::Vector3f p = cam_T_occ * om->corner(k);
    if (!(p.z() > 0.0f)) {
      occ->box = RayBox::All();
      break;
    }
    occ->box.Add(p);
  }
  return Status::Ok();
}

// The edges of one model seen by one camera, sampled and tested for occlusion edge by edge.
class EdgeSampler {
 public:
  EdgeSampler(const Model& m, const RigidTransform& cam_T_model, const CameraIntrinsics& cam,
              float sample_step_px, const Occluder* occ, size_t n_occluders)
      : model_(m),
        cam_T_model_(cam_T_model),
        cam_(cam),
        sample_step_px_(sample_step_px),
        occ_(occ),
        n_occluders_(n_occluders),
        centre_model_(cam_T_model.Inverse().t_mm.cast<double>()),
        front_(FrontFaceMask(m, centre_model_)) {
    // Ray boxes of the front faces (all corners are in front of the camera, checked before).
    for (int f = 0; f < model_.n_faces; ++f) {
      if (!(front_ & (uint64_t{1} << f))) continue;
      for (int k = 0; k < model_.faces[f].n_vertices; ++k) {
        face_box_[f].Add(cam_T_model_ * model_.corner(model_.faces[f].vertices[k]));
      }
    }
  }

  // Adds edge e to `out` when a face next to it is turned to the camera (a candidate), with
  // the runs of its samples that nothing hides (kept when there is one).
  void AddEdge(int e, VisibleEdgeSet* out) {
    const ModelEdge& edge = model_.edges[e];
    const uint64_t adjacent = (uint64_t{1} << edge.face0) | (uint64_t{1} << edge.face1);
    if (!(front_ & adjacent)) return;  // both faces turned away: hidden
    // A facet edge of a curved surface shows only on its silhouette; between two facets turned
    // to the camera the surface runs on without a visible edge.
    if (edge.smooth && (front_ & adjacent) == adjacent) return;
    ++out->n_candidate_edges;

    VisibleEdge& ve = out->edges[out->n_edges];
    ve = VisibleEdge{};
    ve.edge = static_cast<uint8_t>(e);
    ve.a_cam_mm = cam_T_model_ * model_.corner(edge.a);
    ve.b_cam_mm = cam_T_model_ * model_.corner(edge.b);
    // Projected length without distortion decides the number of samples.
    const double dx = cam_.fx * (double{ve.a_cam_mm.x()} / ve.a_cam_mm.z() -
                                 double{ve.b_cam_mm.x()} / ve.b_cam_mm.z());
    const double dy = cam_.fy * (double{ve.a_cam_mm.y()} / ve.a_cam_mm.z() -
                                 double{ve.b_cam_mm.y()} / ve.b_cam_mm.z());
    const double n_wanted = std::ceil(std::sqrt(dx * dx + dy * dy) / sample_step_px_);
    const int n = static_cast<int>(std::max(1.0, std::min<double>(kMaxSamplesPerEdge, n_wanted)));
    ve.n_samples = static_cast<uint16_t>(n);
    out->n_candidate_samples += n;

    // Self-occlusion is tested in the model frame against front faces other than the edge's own
    // (the sample lies on those, exactly at the ray's end).
    RayBox edge_box;
    edge_box.Add(ve.a_cam_mm);
    edge_box.Add(ve.b_cam_mm);
    const float edge_far_z = std::max(ve.a_cam_mm.z(), ve.b_cam_mm.z());
    uint64_t self_mask = 0;
    for (int f = 0; f < model_.n_faces; ++f) {
      if ((front_ & ~adjacent & (uint64_t{1} << f)) && face_box_[f].MayHide(edge_box, edge_far_z)) {
        self_mask |= uint64_t{1} << f;
      }
    }
    if (self_mask != 0 && shape_ == Shape::kUnknown) {
      shape_ = IsConvex(model_) ? Shape::kConvex : Shape::kOther;
    }
    if (shape_ == Shape::kConvex) self_mask = 0;
    uint32_t relevant_occluders = 0;
    for (size_t i = 0; i < n_occluders_; ++i) {
      if (occ_[i].box.MayHide(edge_box, edge_far_z)) relevant_occluders |= 1u << i;
    }
    SampleRuns(edge, self_mask, relevant_occluders, &ve, out);
    if (ve.n_runs > 0) ++out->n_edges;
  }

 private:
  // The n_samples samples of `ve` (edge `edge`), each visible unless a face of `self_mask` or
  // an occluder of `relevant_occluders` hides it, as runs of visible samples.
  void SampleRuns(const ModelEdge& edge, uint64_t self_mask, uint32_t relevant_occluders,
                  VisibleEdge* ve_out, VisibleEdgeSet* out) const {
    VisibleEdge& ve = *ve_out;
    const int n = ve.n_samples;
    const Eigen::Vector3d a_m = model_.corner(edge.a).cast<double>();
    const Eigen::Vector3d ab_m = model_.corner(edge.b).cast<double>() - a_m;
    const double az = ve.a_cam_mm.z(), bz = ve.b_cam_mm.z();
    enum class Run { kNone, kOpen, kDropped } run = Run::kNone;
    for (int i = 0; i < n; ++i) {
      const double s = (i + 0.5) / n;
      const double t = s * az / ((1.0 - s) * bz + s * az);
      bool visible = !(self_mask && RayBlocked(model_, self_mask, centre_model_, a_m + t * ab_m));
      if (visible && relevant_occluders != 0) {
        const Eigen::Vector3d x_cam =
            ve.a_cam_mm.cast<double>() + t * (ve.b_cam_mm - ve.a_cam_mm).cast<double>();
        visible = !BlockedByOccluders(occ_, n_occluders_, relevant_occluders, x_cam);
      }
      if (!visible) {
        run = Run::kNone;
        continue;
      }
      if (run == Run::kNone) {
        if (ve.n_runs < kMaxVisibleRunsPerEdge) {
          ve.runs[ve.n_runs++] = {static_cast<uint16_t>(i), static_cast<uint16_t>(i)};
          run = Run::kOpen;
        } else {
          ++out->dropped_runs;
          run = Run::kDropped;
        }
      }
      if (run == Run::kOpen) {
        ve.runs[ve.n_runs - 1].end = static_cast<uint16_t>(i + 1);
        ++out->n_visible_samples;
      }
    }
  }

  const Model& model_;
  const RigidTransform cam_T_model_;
  const CameraIntrinsics& cam_;
  const float sample_step_px_;
  const Occluder* const occ_;
  const size_t n_occluders_;
  const Eigen::Vector3d centre_model_;  // the camera centre, model frame
  const uint64_t front_;                // faces turned to the camera
  RayBox face_box_[kMaxModelFaces];     // of the front faces
  // Whether the model is convex, found when an edge first has faces that may hide it.
  enum class Shape { kUnknown, kConvex, kOther } shape_ = Shape::kUnknown;
};

}  // namespace

Status CheckModel(const Model& m) {
  if (m.n_corners > kMaxModelCorners || m.n_edges > kMaxModelEdges || m.n_faces > kMaxModelFaces) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "model '%.31s': %d corners, %d edges, %d faces exceed %d/%d/%d", m.name,
                         m.n_corners, m.n_edges, m.n_faces, kMaxModelCorners, kMaxModelEdges,
                         kMaxModelFaces);
  }
  for (int e = 0; e < m.n_edges; ++e) {
    const ModelEdge& edge = m.edges[e];
    if (edge.a >= m.n_corners || edge.b >= m.n_corners || edge.face0 >= m.n_faces ||
        edge.face1 >= m.n_faces) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "model '%.31s': edge %d refers to a missing corner or face", m.name, e);
    }
  }
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    if (face.n_vertices < 3 || face.n_vertices > kMaxFaceVertices) {
      return Status::Error(StatusCode::kInvalidArgument, "model '%.31s': face %d has %d vertices",
                           m.name, f, face.n_vertices);
    }
    for (int k = 0; k < face.n_vertices; ++k) {
      if (face.vertices[k] >= m.n_corners) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "model '%.31s': face %d refers to missing corner %d", m.name, f,
                             face.vertices[k]);
      }
    }
    const double n2 = double{face.normal[0]} * face.normal[0] +
                      double{face.normal[1]} * face.normal[1] +
                      double{face.normal[2]} * face.normal[2];
    if (!(std::fabs(n2 - 1.0) < 1e-3)) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "model '%.31s': face %d normal is not a unit vector", m.name, f);
    }
  }
  return Status::Ok();
}

float MinCornerDepthMm(const ViewCamera& camera, const PosedModel& object) {
  const RigidTransform cam_T_model = camera.cam_T_left * object.cam_T_model;
  float min_z = INFINITY;
  for (int i = 0; i < object.model->n_corners; ++i) {
    min_z = std::min(min_z, (cam_T_model * object.model->corner(i)).z());
  }
  return min_z;
}

double MaxImageRadius2(const CameraIntrinsics& cam) {
  double r2 = 0;
  const double xs[2] = {-0.5, cam.width - 0.5};
  const double ys[2] = {-0.5, cam.height - 0.5};
  for (double x : xs) {
    for (double y : ys) r2 = std::max(r2, UndistortPixel(cam, {x, y}).squaredNorm());
  }
  // 20 % margin in radius: points just outside the corners still project outside the image.
  return r2 * 1.44;
}

bool ProjectInView(const CameraIntrinsics& cam, double max_radius2, const Eigen::Vector3f& x_cam,
                   Eigen::Vector2f* pixel) {
  if (!(x_cam.z() > 0.0f)) return false;
  const double x = double{x_cam.x()} / x_cam.z(), y = double{x_cam.y()} / x_cam.z();
  if (!(x * x + y * y <= max_radius2)) return false;
  const Eigen::Vector2d d = Distort(cam, {x, y});
  *pixel = {static_cast<float>(cam.fx * d.x() + cam.cx),
            static_cast<float>(cam.fy * d.y() + cam.cy)};
  return true;
}

Status ComputeVisibleEdges(const ViewCamera& camera, const PosedModel& object,
                           const PosedModel* occluders, size_t n_occluders, float sample_step_px,
                           float min_depth_mm, VisibleEdgeSet* out) {
  if (out == nullptr || object.model == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "visible edges: null model or output");
  }
  SH_RETURN_IF_ERROR(
      CheckVisibleEdgeInputs(camera, object, occluders, n_occluders, sample_step_px, min_depth_mm));
  // Occluders in this camera's frame, with the faces they turn towards it.
  Occluder occ[kMaxOccluders];
  for (size_t i = 0; i < n_occluders; ++i) {
    SH_RETURN_IF_ERROR(PlaceOccluder(camera, occluders[i], i, &occ[i]));
  }
  EdgeSampler sampler(*object.model, camera.cam_T_left * object.cam_T_model, camera.intrinsics,
                      sample_step_px, occ, n_occluders);
  *out = VisibleEdgeSet{};
  for (int e = 0; e < object.model->n_edges; ++e) sampler.AddEdge(e, out);
  return Status::Ok();
}

}  // namespace sh
