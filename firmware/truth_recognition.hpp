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
  Status Init(const StereoCalibration& calib, const TableView& table, uint32_t model_mask) override;
  Status SetModelMask(uint32_t model_mask) override {
    mask_ = model_mask;
    return Status::Ok();
  }
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;

 private:
  const render::SimWorld* world_;
  uint32_t mask_ = 0;
  int table_id_of_world_model_[kMaxFolderModels] = {};
};

// Table model id of each world model, by name (-1 when the table lacks it): the tables may come
// from a file built from another model folder than the one the world renders.
void MapWorldModelsToTable(const render::SimWorld& world, const TableView& table, int* ids);

}  // namespace sh::fw
