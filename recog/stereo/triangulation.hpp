// Triangulation of points (two viewing rays) and lines (two back-projected planes), and the
// back-projection of 2-D line support onto a 3-D line. All 3-D quantities are in the left camera
// frame, millimetres; the right camera centre is RightCentreInLeft(calib).
#pragma once

#include <Eigen/Core>

#include "recog/camera/camera_model.hpp"

namespace sh {

// Result of intersecting two rays origin + t * direction (unit directions).
struct RayMidpoint {
  Eigen::Vector3d p_mm = Eigen::Vector3d::Zero();  // midpoint of the shortest segment
  double gap_mm = 0.0;                             // length of that segment
  double depth_a_mm = 0.0;                         // ray parameters of its end points; > 0 means
  double depth_b_mm = 0.0;                         // in front of the ray's origin
};

// Midpoint of the shortest segment between two rays. False when they are (nearly) parallel:
// sin(angle) below 1e-9 leaves the midpoint undefined.
bool TriangulateMidpoint(const Eigen::Vector3d& origin_a, const Eigen::Vector3d& direction_a,
                         const Eigen::Vector3d& origin_b, const Eigen::Vector3d& direction_b,
                         RayMidpoint* out);

// Midpoint triangulation of a left and a right pixel (distorted, as detected).
bool TriangulatePixels(const StereoCalibration& calib, const Eigen::Vector2d& left_px,
                       const Eigen::Vector2d& right_px, RayMidpoint* out);

// Plane n . x = d with |n| = 1.
struct Plane3 {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d_mm = 0.0;
};

// Infinite 3-D line point + s * direction, |direction| = 1, s in millimetres.
struct Line3 {
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  Eigen::Vector3d At(double s_mm) const { return point_mm + s_mm * direction; }
};

// Unit normal, in the camera's own frame, of the plane through the camera centre that contains
// the viewing rays of `count` (>= 2) pixels of one 2-D line. With distortion the rays of a
// straight image line are not exactly coplanar; the plane is the least-squares fit (normal =
// least eigenvector of sum r r^T over the unit rays). False when the rays do not span a plane.
bool FitLinePlaneNormal(const CameraIntrinsics& cam, const Eigen::Vector2d* pixels, int count,
                        Eigen::Vector3d* normal_cam);

// Intersection line of two planes. False when the angle between them is below the angle whose
// sine is min_sin_angle (nearly parallel planes: for stereo, a line close to the epipolar
// direction). The line's point is the one closest to the origin.
bool IntersectPlanes(const Plane3& a, const Plane3& b, double min_sin_angle, Line3* line);

// Parameter s on `line` of the point closest to the ray origin + t * direction (unit): where the
// viewing ray of an image point meets the 3-D line that lies in its back-projected plane. False
// when the ray is nearly parallel to the line or meets it behind its origin.
bool RayLineParameter(const Line3& line, const Eigen::Vector3d& origin,
                      const Eigen::Vector3d& direction, double* s_mm);

}  // namespace sh
