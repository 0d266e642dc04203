// The rotation between two poses of a model, up to the model's own symmetries: a cube turned a
// quarter about an axis is the same cube.
#pragma once

#include <Eigen/Core>
#include <algorithm>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"

namespace sh::testing {

// Degrees between rotations a and b, the least over the model's stored symmetries.
inline float SymmetricAngleDeg(const Model& m, const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
  float best = 180;
  for (int k = 0; k < m.n_symmetries; ++k) {
    best = std::min(best, RotationAngleDeg(a.transpose() * b * m.symmetry(k)));
  }
  return best;
}

}  // namespace sh::testing
