#include "recog/hashing/basis.hpp"

#include <cmath>

namespace sh {
namespace {

RigidTransform FrameFromAxes(const Eigen::Vector3f& x, const Eigen::Vector3f& y,
                             const Eigen::Vector3f& origin) {
  RigidTransform basis_T_world;
  basis_T_world.R.row(0) = x;
  basis_T_world.R.row(1) = y;
  basis_T_world.R.row(2) = x.cross(y);
  basis_T_world.t_mm = -(basis_T_world.R * origin);
  return basis_T_world;
}

}  // namespace

bool ThreePointFrame(HashFunction hf, const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                     const Eigen::Vector3f& p2, const BasisLimits& limits,
                     RigidTransform* basis_T_world) {
  const Eigen::Vector3f d01 = p1 - p0, d02 = p2 - p0, d12 = p2 - p1;
  const float a = d01.norm(), b = d02.norm(), c = d12.norm();
  const float shortest = std::min(a, std::min(b, c));
  const float longest = std::max(a, std::max(b, c));
  if (shortest < limits.min_point_spacing_mm || longest > limits.max_point_spacing_mm) return false;
  const Eigen::Vector3f x = d01 / a;
  const Eigen::Vector3f y_raw = d02 - d02.dot(x) * x;
  const float height = y_raw.norm();
  if (height < limits.min_triangle_height_mm) return false;
  const Eigen::Vector3f origin = hf == HashFunction::kThreePointsFirst ? p0 : (p0 + p1 + p2) / 3.0f;
  *basis_T_world = FrameFromAxes(x, y_raw / height, origin);
  return true;
}

Eigen::Vector3f TriangleShapePoint(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                                   const Eigen::Vector3f& p2) {
  const Eigen::Vector3f d01 = p1 - p0, d02 = p2 - p0;
  const float a = d01.norm();
  const Eigen::Vector3f x = d01 / a;
  const float x2 = d02.dot(x);
  return {a, x2, (d02 - x2 * x).norm()};
}

bool TwoLineFrame(const BasisLine3& l0, const BasisLine3& l1, const BasisLimits& limits,
                  RigidTransform* basis_T_world) {
  const Eigen::Vector3f& u = l0.direction;
  const Eigen::Vector3f& v = l1.direction;
  const float cos_angle = std::fabs(u.dot(v));
  if (cos_angle > std::cos(limits.min_line_angle_deg * float(M_PI) / 180.0f)) return false;
  // Closest points l0.point + s u and l1.point + t v (unit directions, non-parallel).
  const Eigen::Vector3f w = l0.point - l1.point;
  const float b = u.dot(v), d = u.dot(w), e = v.dot(w);
  const float denom = 1.0f - b * b;
  const float s = (b * e - d) / denom;
  const float t = (e - b * d) / denom;
  const Eigen::Vector3f c0 = l0.point + s * u, c1 = l1.point + t * v;
  if ((c0 - c1).norm() > limits.max_line_distance_mm) return false;
  const Eigen::Vector3f y_raw = v - v.dot(u) * u;
  *basis_T_world = FrameFromAxes(u, y_raw.normalized(), 0.5f * (c0 + c1));
  return true;
}

float PointLineDistance(const BasisLine3& line, const Eigen::Vector3f& point) {
  const Eigen::Vector3f w = point - line.point;
  return (w - w.dot(line.direction) * line.direction).norm();
}

bool LinePointFrame(HashFunction hf, const BasisLine3& line, const Eigen::Vector3f& point,
                    const BasisLimits& limits, RigidTransform* basis_T_world) {
  const Eigen::Vector3f w = point - line.point;
  const Eigen::Vector3f foot = line.point + w.dot(line.direction) * line.direction;
  const Eigen::Vector3f to_point = point - foot;
  const float distance = to_point.norm();
  if (distance < limits.min_point_line_mm || distance > limits.max_point_line_mm) return false;
  const Eigen::Vector3f origin = hf == HashFunction::kLinePointFoot ? foot : 0.5f * (foot + point);
  *basis_T_world = FrameFromAxes(line.direction, to_point / distance, origin);
  return true;
}

}  // namespace sh
