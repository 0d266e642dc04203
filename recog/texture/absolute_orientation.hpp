// Horn's closed-form absolute orientation with unit quaternions (J. Opt. Soc. Am. A 4(4), 1987):
// the rigid transform that best maps one point set onto another in the least-squares sense.
#pragma once

#include <Eigen/Core>

#include "recog/geometry/rigid_transform.hpp"

namespace sh::texture {

// b_T_a minimising sum_i w_i |b_i - (R a_i + t)|^2 over `count` pairs (weights may be null: all
// 1). The rotation is the eigenvector of the largest eigenvalue of Horn's symmetric 4 x 4 matrix
// N, as a unit quaternion. False for fewer than three pairs or a degenerate configuration
// (points collinear: the rotation about their line is undetermined).
bool AbsoluteOrientation(const Eigen::Vector3d* a, const Eigen::Vector3d* b, const double* weights,
                         int count, RigidTransform* b_T_a);

}  // namespace sh::texture
