#include "firmware/truth_recognition.hpp"

namespace sh::fw {

void MapWorldModelsToIds(const render::SimWorld& world, const ModelSet& models, int* ids) {
  for (int m = 0; m < world.model_count(); ++m) ids[m] = models.Find(world.models()[m].name);
}

Status TruthRecognition::Init(const StereoCalibration& calib, const ModelSet& models,
                              uint32_t model_mask) {
  mask_ = model_mask;
  MapWorldModelsToIds(*world_, models, id_of_world_model_);
  return Status::Ok();
}

Status TruthRecognition::Process(const hal::StereoFrame& frame, float budget_ms,
                                 protocol::ResultSet* set) {
  const render::GeneratedScene& g = world_->scene(world_->SceneOfFrame(frame.left_sequence));
  uint8_t instances[32] = {};
  size_t n = 0;
  for (size_t i = 0; i < g.scene.objects.size() && n < protocol::kMaxResultObjects; ++i) {
    const int id = id_of_world_model_[g.scene.objects[i].model_index];
    if (id < 0 || id > 31 || !(mask_ & (1u << id))) continue;
    set->objects[n++] =
        protocol::MakeObjectPose(g.left_T_model[i], static_cast<uint8_t>(id), instances[id]++, 1.0);
  }
  set->object_count = static_cast<uint8_t>(n);
  set->status = protocol::ResultStatus::kOk;
  return Status::Ok();
}

}  // namespace sh::fw
