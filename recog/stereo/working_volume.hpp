// The region of space where objects can be: stereo keeps only 3-D features inside it, and clips
// 3-D lines to it before comparing their supports (thesis: 400 x 400 x 70 mm above the table).
//
// The volume is an axis-aligned box in its own frame, placed in the left camera frame by
// left_T_box. With the identity transform the box is simply given in left camera coordinates
// (x right, y down, z forward); for a table, left_T_box is the table pose (e.g. from a
// calibration target lying on it) and the box runs from the table surface z = 0 upwards.
#pragma once

#include <Eigen/Core>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {

inline constexpr float kTableVolumeBelowMm = 3.0f;
inline constexpr float kTableVolumeHeightMm = 150.0f;
inline constexpr float kTableVolumeHalfWidthMm = 1000.0f;

struct WorkingVolume {
  RigidTransform left_T_box = RigidTransform::Identity();
  Eigen::Vector3f min_mm = Eigen::Vector3f(-1000.0f, -1000.0f, 100.0f);
  Eigen::Vector3f max_mm = Eigen::Vector3f(1000.0f, 1000.0f, 3000.0f);

  // A box given directly in the left camera frame.
  static WorkingVolume InLeftCamera(const Eigen::Vector3f& min_mm, const Eigen::Vector3f& max_mm);
  // A box in a table frame; left_T_table maps table coordinates into the left camera frame.
  static WorkingVolume InFrame(const RigidTransform& left_T_table, const Eigen::Vector3f& min_mm,
                               const Eigen::Vector3f& max_mm);
  // The space over a table of known pose: kTableVolumeBelowMm under its top (bottom edges whose
  // triangulation errs downwards stay; mirror images in a glossy table and shadows on it go) up
  // to kTableVolumeHeightMm, kTableVolumeHalfWidthMm to either side of its origin.
  static WorkingVolume OverTable(const RigidTransform& left_T_table);

  bool Contains(const Eigen::Vector3d& p_left_mm) const;

  // Parameter interval [s0, s1] of `line_left` (left camera frame) inside the box. False when
  // the line misses the box.
  bool Clip(const Line3& line_left, double* s0_mm, double* s1_mm) const;
};

}  // namespace sh
