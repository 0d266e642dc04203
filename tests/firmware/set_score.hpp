// A result set scored against the rendered truth of one of the simulated world's scenes, for the
// firmware tests that run the real recognition on the simulator.
#pragma once

#include <Eigen/Geometry>

#include "firmware/result_codec.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "recog/mono/aspect.hpp"
#include "tables/table_view.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh::testing {

struct SetScore {
  int truth = 0, correct = 0, false_alarms = 0;
};

// Objects of a set against the truth of scene `scene`: same model, corner centroid (which the
// model's symmetries fix) within 5 mm, rotation within 5 degrees modulo the symmetries (the
// tables' models carry them); each truth object matches once. Allocates nothing.
inline SetScore ScoreSetOnScene(const render::SimWorld& world, const TableView& table,
                                const int* table_ids, int scene, const protocol::ResultSet& set) {
  const render::GeneratedScene& g = world.scene(scene);
  bool used[render::kMaxRenderObjects] = {};
  SetScore score;
  score.truth = static_cast<int>(g.scene.objects.size());
  for (int i = 0; i < set.object_count; ++i) {
    const protocol::ObjectPose& p = set.objects[i];
    const Model& model = table.model(p.model_id);
    const RigidTransform found = protocol::PoseTransform(p);
    const Eigen::Vector3f centroid = ModelCentroid(model);
    bool matched = false;
    for (size_t k = 0; k < g.scene.objects.size() && !matched; ++k) {
      if (used[k] || table_ids[g.scene.objects[k].model_index] != p.model_id) continue;
      const RigidTransform& truth = g.left_T_model[k];
      const float position_mm = (truth * centroid - found * centroid).norm();
      const float rotation_deg = SymmetricRotationErrorDeg(model, found.R, truth.R);
      if (position_mm <= 5.0f && rotation_deg <= 5.0f) used[k] = matched = true;
    }
    ++(matched ? score.correct : score.false_alarms);
  }
  return score;
}

}  // namespace sh::testing
