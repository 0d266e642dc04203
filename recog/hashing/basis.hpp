// Basis frames of the five 3-D hash functions (thesis table 5.1).
//
// A basis is a small set of features (three points, two lines, or a line and a point) that fixes
// a right-handed orthonormal frame. Expressing every other feature in that frame makes its
// coordinates invariant to the rigid motion of the object, which is what the hash arrays index.
//
// | hash fn | basis            | origin                                              |
// | 1       | 3 points         | first point                                         |
// | 2       | 3 points         | centroid of the three points                        |
// | 3       | 2 lines          | midpoint of the common perpendicular                |
// | 4       | line + point     | foot of the perpendicular from the point on the line|
// | 5       | line + point     | midway between that foot and the point              |
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/geometry/rigid_transform.hpp"
#include "tables/table_format.hpp"  // HashFunction, BasisLimits: the table format's vocabulary

namespace sh {

// An infinite line through `point` with unit `direction`; the sign of direction matters for
// frames (it picks one of the frames a line basis allows).
struct BasisLine3 {
  Eigen::Vector3f point;
  Eigen::Vector3f direction;
};

// Frame of three points (hash fns 1, 2). Returns false for a degenerate triangle.
bool ThreePointFrame(HashFunction hf, const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                     const Eigen::Vector3f& p2, const BasisLimits& limits,
                     RigidTransform* basis_T_world);

// The three free shape parameters of a three-point basis stored as one artificial point:
// (|p1 - p0|, x of p2, y of p2) in the frame with origin p0.
Eigen::Vector3f TriangleShapePoint(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1,
                                   const Eigen::Vector3f& p2);

// Frame of two lines (hash fn 3): x along l0, xy-plane spanned by both directions.
bool TwoLineFrame(const BasisLine3& l0, const BasisLine3& l1, const BasisLimits& limits,
                  RigidTransform* basis_T_world);

// Frame of a line and a point off it (hash fns 4, 5): x along the line, y towards the point.
bool LinePointFrame(HashFunction hf, const BasisLine3& line, const Eigen::Vector3f& point,
                    const BasisLimits& limits, RigidTransform* basis_T_world);

// Distance from a point to an infinite line.
float PointLineDistance(const BasisLine3& line, const Eigen::Vector3f& point);

// Support vector of a line: its point closest to the origin.
inline Eigen::Vector3f SupportVector(const Eigen::Vector3f& point,
                                     const Eigen::Vector3f& unit_dir) {
  return point - point.dot(unit_dir) * unit_dir;
}

}  // namespace sh
