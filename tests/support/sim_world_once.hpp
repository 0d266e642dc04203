// The simulated world of a firmware test program, built once and shared by its tests.
#pragma once

#include <gtest/gtest.h>

#include "hal/sim/world/sim_world.hpp"

namespace sh::testing {

// Builds `world` from `config` unless it is built already. Rendering a world takes seconds and
// the world is read-only afterwards, so the tests of one program share one (a function-local
// static) built from one configuration. A failure names the world's error and leaves the world
// unbuilt, so the next test tries again and fails the same way.
inline ::testing::AssertionResult BuildOnce(render::SimWorld& world,
                                            const render::SimWorldConfig& config) {
  if (world.built()) return ::testing::AssertionSuccess();
  const Status built = world.Build(config);
  if (!built.ok()) return ::testing::AssertionFailure() << "simulated world: " << built.message();
  return ::testing::AssertionSuccess();
}

}  // namespace sh::testing
