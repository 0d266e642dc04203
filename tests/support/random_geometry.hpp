// Random geometry for tests that sweep many cases from a seeded generator.
#pragma once

#include <Eigen/Core>
#include <random>

namespace sh::testing {

// A direction drawn uniformly from the unit sphere (a normalised isotropic Gaussian).
inline Eigen::Vector3f RandomUnit(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  return Eigen::Vector3f(n(rng), n(rng), n(rng)).normalized();
}

}  // namespace sh::testing
