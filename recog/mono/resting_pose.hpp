// Objects resting on a known plane (the table): the stable faces of a model and the poses in
// which it rests on one of them. With the table's pose, a resting object keeps three free
// parameters (its heading about the table normal and its position on the table): one image
// then fixes depth and tilt (thesis ch. 6 had no such constraint and suffered from wrong sizes
// and degenerate views).
//
// Stable faces are the faces of the convex hull whose plane holds the centre of mass above the
// inside of the face (a star prism rests on its side on two of its points, where no model face
// is).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"

namespace sh {

inline constexpr int kMaxStableFaces = 64;

struct StableFace {
  Eigen::Vector3f normal_model{0, 0, -1};  // outward unit normal of the hull face
  float offset_mm = 0;                     // plane: normal . x = offset_mm (model frame)
  float area_mm2 = 0;
};

struct StableFaces {
  int count = 0;
  StableFace faces[kMaxStableFaces];
};

// Smallest rotation turning unit vector a onto unit vector b.
Eigen::Matrix3f RotationBetween(const Eigen::Vector3f& a, const Eigen::Vector3f& b);

// Centre of mass of the solid (uniform density), from the closed polygon surface.
Eigen::Vector3f SolidCentroid(const Model& model);

// The stable faces of the model's convex hull: the centre of mass projects inside the face by at
// least margin_mm. Errors: an invalid model, more stable faces than kMaxStableFaces.
Status ComputeStableFaces(const Model& model, float margin_mm, StableFaces* out);

// The table: x_cam = cam_R_table x_table + cam_t_table, table z up, top at z = 0 (millimetres).
struct TablePlane {
  RigidTransform cam_T_table;
};

// A resting pose: the model lies on stable face `face`, turned by heading_rad about the table
// normal, its origin above the table point (x_mm, y_mm).
struct RestingPose {
  int face = 0;
  float heading_rad = 0;
  float x_mm = 0, y_mm = 0;
};

// Rotation table_R_model of a model resting on face `f` with heading 0 (a fixed choice of the
// rotation that turns the face's normal to -z).
Eigen::Matrix3f RestingRotation(const StableFace& f);

// cam_T_model of a resting pose.
RigidTransform RestingTransform(const TablePlane& table, const StableFaces& faces,
                                const RestingPose& pose);

// The resting pose nearest to `cam_T_model`: the stable face whose normal is closest to the
// table's downward direction, the rotation corrected by the smallest turn that lays that face
// flat, and the model origin moved along its viewing ray (from the camera centre) to its height
// above the table. False when no face is within max_tilt_deg of lying flat or the ray does not
// meet that height in front of the camera.
bool NearestRestingPose(const TablePlane& table, const StableFaces& faces,
                        const RigidTransform& cam_T_model, float max_tilt_deg, RestingPose* out,
                        float* tilt_deg = nullptr);

// The resting pose on face `face` nearest to cam_T_model: its rotation corrected by the
// smallest turn that lays the face flat; the model origin moved along its viewing ray to its
// height above the table. False when the ray does not meet that height in front of the camera.
bool RestingPoseOnFace(const TablePlane& table, const StableFaces& faces, int face,
                       const RigidTransform& cam_T_model, RestingPose* out);

// The resting pose on face `face` that puts the model corners a_model and b_model on the viewing
// rays ray_a and ray_b (camera frame, from the camera centre): each corner's ray meets the plane
// of its height above the table, and the heading turns the corners' horizontal offset onto the
// offset of those two points. *length_ratio: observed over model horizontal distance (about 1
// when the corners and the face are right). False when a ray does not reach its height in front
// of the camera or the two corners lie nearly above each other (horizontal offset under
// min_offset_mm: the heading is not determined).
bool RestingPoseFromCorners(const TablePlane& table, const StableFaces& faces, int face,
                            const Eigen::Vector3f& a_model, const Eigen::Vector3f& b_model,
                            const Eigen::Vector3f& ray_a, const Eigen::Vector3f& ray_b,
                            float min_offset_mm, RestingPose* out, float* length_ratio);

}  // namespace sh
