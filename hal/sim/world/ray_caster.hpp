// Ray casting against the polyhedra of a RenderScene and the table plane, in the table frame.
// Faces are intersected as planes and tested point-in-polygon (crossing number, so non-convex
// faces such as the star's work); each object is culled by its bounding sphere first.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "hal/sim/world/render_scene.hpp"
#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh::render {

inline constexpr int kTableHit = 0xff;  // Hit::object for the table plane
// Face corners of all objects together (a can has 288, the reference polyhedra at most 60).
inline constexpr int kMaxRenderFaceVertices = 8192;
inline constexpr int kNoHit = 0xfe;

struct Hit {
  float t_mm = 0;  // distance along the (unit) ray
  int object = kNoHit;
  int face = 0;
};

class RayCaster {
 public:
  // Transforms every object's faces into the table frame. Fails on bad model indices.
  Status Prepare(const RenderScene& scene, const Model* models, int n_models);

  // Nearest front-facing surface along o + t d (|d| = 1, t > 0), objects or table.
  Hit Cast(const Eigen::Vector3f& o, const Eigen::Vector3f& d) const;
  // True if an object blocks o + t d for 0 < t < t_max (shadow rays).
  bool Blocked(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t_max) const;

  Eigen::Vector3f normal(const Hit& hit) const;
  float albedo(int object) const { return objects_[object].albedo; }
  int n_objects() const { return n_objects_; }

 private:
  struct Face {
    Eigen::Vector3f normal;
    float offset = 0;      // normal . x = offset on the face plane
    uint8_t u = 0, v = 1;  // table axes kept for the 2-D point-in-polygon test
    uint8_t n = 0;
    uint16_t first = 0;  // polygon corners: poly_[first .. first + n)
  };
  struct Object {
    Eigen::Vector3f centre;
    float radius_sq = 0;
    float albedo = 0;
    int n_faces = 0;
    Face faces[kMaxModelFaces];
  };

  bool MayHit(const Object& obj, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
              float t_max) const;
  bool HitsFace(const Face& f, const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t_max,
                float* t) const;

  int n_objects_ = 0;
  Object objects_[kMaxRenderObjects];
  int n_poly_ = 0;
  float poly_[kMaxRenderFaceVertices][2];
};

}  // namespace sh::render
