// Recognition through the recognition pipeline (recog/pipeline): the board's recogniser.
#pragma once

#include "firmware/recognition.hpp"
#include "recog/pipeline/pipeline.hpp"

namespace sh::fw {

struct PipelineRecognitionConfig {
  bool automatic = true;          // thresholds measured from each image (no preset)
  bool light_background = false;  // without `automatic`: the light-table preset
  int threads = 0;                // worker threads, the calling one included; 0 = all cores
  bool table_known = false;       // left_T_table is the table the objects stand on
  bool volume_set = false;        // working volume box, in the left camera or the table frame
  float volume_min_mm[3] = {0, 0, 0};
  float volume_max_mm[3] = {0, 0, 0};
  bool volume_in_table_frame = false;
  // No box given but a table pose known: the space over the table (WorkingVolume::OverTable),
  // as `stereohash recognize --table` bounds it.
  bool volume_over_table = false;
  RigidTransform left_T_table;  // table (conveyor) frame -> left camera, mm
  // When set, read at each Init() in place of left_T_table: the simulator's rendered table,
  // known only once its world is built.
  const RigidTransform* left_T_table_at_init = nullptr;
};

class PipelineRecognition final : public Recognition {
 public:
  // `pipeline` is large (tens of MiB): the caller keeps it in static storage.
  PipelineRecognition(Pipeline* pipeline, const PipelineRecognitionConfig& config)
      : pipeline_(pipeline), config_(config) {}

  Status Init(const StereoCalibration& calib, const TableView& table, uint32_t model_mask) override;
  Status SetModelMask(uint32_t model_mask) override;
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;

 private:
  Pipeline* pipeline_;
  PipelineRecognitionConfig config_;
  PipelineResult result_;
};

}  // namespace sh::fw
