#include "hal/sim/world/ray_caster.hpp"

#include <cmath>
#include <limits>

namespace sh::render {
namespace {

// Rays start this far off the surface they leave, so they do not hit it again (mm).
constexpr float kEpsilonMm = 1e-3f;

}  // namespace

Status RayCaster::Prepare(const RenderScene& scene, const Model* models, int n_models) {
  n_objects_ = 0;
  n_poly_ = 0;
  for (const SceneObject& so : scene.objects) {
    if (so.model_index >= n_models) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "render: object %d uses model %d but only %d models are loaded",
                           n_objects_, so.model_index, n_models);
    }
    const Model& m = models[so.model_index];
    if (m.n_faces == 0 || m.n_faces > kMaxModelFaces || m.n_corners > kMaxModelCorners) {
      return Status::Error(StatusCode::kInvalidArgument, "render: model '%s' has no usable faces",
                           m.name);
    }
    Object& obj = objects_[n_objects_];
    obj.albedo = so.albedo;
    obj.n_faces = m.n_faces;
    Eigen::Vector3f corners[kMaxModelCorners];
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (int i = 0; i < m.n_corners; ++i) {
      corners[i] = so.table_T_model * m.corner(i);
      centre += corners[i];
    }
    centre /= static_cast<float>(m.n_corners);
    float r2 = 0;
    for (int i = 0; i < m.n_corners; ++i) r2 = std::max(r2, (corners[i] - centre).squaredNorm());
    obj.centre = centre;
    obj.radius_sq = r2 * 1.0001f + 1e-3f;
    for (int f = 0; f < m.n_faces; ++f) {
      const ModelFace& mf = m.faces[f];
      if (mf.n_vertices < 3 || mf.n_vertices > kMaxFaceVertices) {
        return Status::Error(StatusCode::kInvalidArgument, "render: model '%s' face %d is bad",
                             m.name, f);
      }
      Face& face = obj.faces[f];
      face.normal = so.table_T_model.Rotate(m.face_normal(f)).normalized();
      face.offset = face.normal.dot(corners[mf.vertices[0]]);
      // Drop the axis along which the normal is largest: the projection stays non-degenerate.
      int drop = 0;
      face.normal.cwiseAbs().maxCoeff(&drop);
      face.u = static_cast<uint8_t>((drop + 1) % 3);
      face.v = static_cast<uint8_t>((drop + 2) % 3);
      face.n = mf.n_vertices;
      if (n_poly_ + mf.n_vertices > kMaxRenderFaceVertices) {
        return Status::Error(StatusCode::kResourceExhausted,
                             "render: the objects have more than %d face corners in total",
                             kMaxRenderFaceVertices);
      }
      face.first = static_cast<uint16_t>(n_poly_);
      for (int k = 0; k < mf.n_vertices; ++k) {
        poly_[n_poly_][0] = corners[mf.vertices[k]][face.u];
        poly_[n_poly_][1] = corners[mf.vertices[k]][face.v];
        ++n_poly_;
      }
    }
    ++n_objects_;
  }
  return Status::Ok();
}

// Bounding-sphere test: false when the ray misses the object's sphere, or meets it only behind
// the origin or beyond t_max, so its faces need not be tested.
bool RayCaster::MayHit(const Object& obj, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                       float t_max) const {
  const Eigen::Vector3f oc = obj.centre - o;
  const float tca = oc.dot(d);
  const float d2 = oc.squaredNorm() - tca * tca;
  if (d2 > obj.radius_sq) return false;
  const float half = std::sqrt(obj.radius_sq - d2);
  return tca + half > kEpsilonMm && tca - half < t_max;
}

bool RayCaster::HitsFace(const Face& f, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                         float t_max, float* t_out) const {
  const float denom = f.normal.dot(d);
  if (denom >= 0) return false;  // back face: a closed solid is always entered through a front face
  const float t = (f.offset - f.normal.dot(o)) / denom;
  if (!(t > kEpsilonMm && t < t_max)) return false;
  const float pu = o[f.u] + t * d[f.u], pv = o[f.v] + t * d[f.v];
  // Crossing-number point-in-polygon test.
  bool inside = false;
  const float(*poly)[2] = poly_ + f.first;
  for (int i = 0, j = f.n - 1; i < f.n; j = i++) {
    const float ui = poly[i][0], vi = poly[i][1];
    const float uj = poly[j][0], vj = poly[j][1];
    if ((vi > pv) != (vj > pv) && pu < (uj - ui) * (pv - vi) / (vj - vi) + ui) inside = !inside;
  }
  if (inside) *t_out = t;
  return inside;
}

Hit RayCaster::Cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d) const {
  Hit best;
  best.t_mm = std::numeric_limits<float>::infinity();
  if (d.z() < 0 && o.z() > 0) {
    best.t_mm = -o.z() / d.z();
    best.object = kTableHit;
  }
  for (int i = 0; i < n_objects_; ++i) {
    const Object& obj = objects_[i];
    if (!MayHit(obj, o, d, best.t_mm)) continue;
    for (int f = 0; f < obj.n_faces; ++f) {
      float t;
      if (HitsFace(obj.faces[f], o, d, best.t_mm, &t)) {
        best.t_mm = t;
        best.object = i;
        best.face = f;
      }
    }
  }
  return best;
}

bool RayCaster::Blocked(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t_max) const {
  for (int i = 0; i < n_objects_; ++i) {
    const Object& obj = objects_[i];
    if (!MayHit(obj, o, d, t_max)) continue;
    for (int f = 0; f < obj.n_faces; ++f) {
      float t;
      if (HitsFace(obj.faces[f], o, d, t_max, &t)) return true;
    }
  }
  return false;
}

Eigen::Vector3f RayCaster::normal(const Hit& hit) const {
  if (hit.object == kTableHit) return Eigen::Vector3f::UnitZ();
  return objects_[hit.object].faces[hit.face].normal;
}

}  // namespace sh::render
