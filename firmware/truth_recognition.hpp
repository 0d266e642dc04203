// Simulator-only recognition that reports the rendered ground truth of the captured frame: it
// exercises capture, CAN publication and timing without depending on recognition quality.
// Part of the simulator program only (firmware/board_sim.cpp), never of the board program.
#pragma once

#include <cstdint>

#include "firmware/recognition.hpp"
#include "hal/sim/world/sim_world.hpp"
#include "tables/model_files.hpp"

namespace sh::fw {

class TruthRecognition final : public Recognition {
 public:
  explicit TruthRecognition(const render::SimWorld* world) : world_(world) {}
  Status Init(const StereoCalibration& calib, const ModelSet& models, uint32_t model_mask) override;
  Status SetModelMask(uint32_t model_mask) override {
    mask_ = model_mask;
    return Status::Ok();
  }
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;

 private:
  const render::SimWorld* world_;
  uint32_t mask_ = 0;
  int id_of_world_model_[render::kMaxWorldModels] = {};
};

// Model id of each world model, by name (-1 when the model set lacks it): the tables and the
// feature database may come from files built from other model folders than the world renders.
void MapWorldModelsToIds(const render::SimWorld& world, const ModelSet& models, int* ids);

}  // namespace sh::fw
