// What the recogniser's parts share about the scene being searched: the scene, which of its
// features are still active (an accepted object's features leave), unit line directions and the
// grid over the points. Owned by the Recognizer; the parts only read it.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/hashing/scene_grid.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

struct SceneState {
  const Scene* scene = nullptr;
  const uint8_t* point_active = nullptr;      // per scene point, 0 or 1
  const uint8_t* line_active = nullptr;       // per scene line
  const Eigen::Vector3f* line_dir = nullptr;  // unit direction a -> b of each line
  const SceneGrid* point_grid = nullptr;
};

}  // namespace sh
