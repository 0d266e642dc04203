#include "firmware/pipeline_recognition.hpp"

#include <algorithm>

#include "firmware/firmware_core.hpp"

namespace sh::fw {

Status PipelineRecognition::Init(const StereoCalibration& calib, const TableView& table,
                                 uint32_t model_mask) {
  // The automatic default or a preset (detectors, verification, search), not bare defaults.
  PipelineConfig config = config_.automatic          ? PipelineConfig::Automatic()
                          : config_.light_background ? PipelineConfig::LightBackground()
                                                     : PipelineConfig::DarkBackground();
  config.threads = config_.threads;
  const RigidTransform& left_T_table = config_.left_T_table_at_init != nullptr
                                           ? *config_.left_T_table_at_init
                                           : config_.left_T_table;
  if (config_.table_known) {
    config.table.known = true;
    config.table.left_T_table = left_T_table;
  }
  if (config_.volume_set) {
    const Eigen::Vector3f min_mm(config_.volume_min_mm[0], config_.volume_min_mm[1],
                                 config_.volume_min_mm[2]);
    const Eigen::Vector3f max_mm(config_.volume_max_mm[0], config_.volume_max_mm[1],
                                 config_.volume_max_mm[2]);
    config.stereo.volume = config_.volume_in_table_frame
                               ? WorkingVolume::InFrame(left_T_table, min_mm, max_mm)
                               : WorkingVolume::InLeftCamera(min_mm, max_mm);
  } else if (config_.volume_over_table) {
    config.stereo.volume = WorkingVolume::OverTable(left_T_table);
  }
  config.recognizer.model_mask = model_mask;
  return pipeline_->Init(calib, table, config, &MonotonicNs);
}

Status PipelineRecognition::SetModelMask(uint32_t model_mask) {
  // Re-initialising with the same calibration and table only reconfigures (no allocation).
  PipelineConfig config = pipeline_->config();
  config.recognizer.model_mask = model_mask;
  const StereoCalibration calib = pipeline_->calibration();
  const TableView table = pipeline_->table();
  return pipeline_->Init(calib, table, config, &MonotonicNs);
}

Status PipelineRecognition::Process(const hal::StereoFrame& frame, float budget_ms,
                                    protocol::ResultSet* set) {
  SH_RETURN_IF_ERROR(pipeline_->Process(frame.left, frame.right, budget_ms, &result_));
  set->status = result_.recognition.budget_exhausted ? protocol::ResultStatus::kTimeBudgetHit
                                                     : protocol::ResultStatus::kOk;
  size_t n = 0;
  for (const RecognizedObject& o : result_.objects) {
    if (n == protocol::kMaxResultObjects) break;
    // The weaker image decides: an object must be confirmed in both views.
    const float score = std::clamp(std::min(o.verify_score[0], o.verify_score[1]), 0.0f, 1.0f);
    set->objects[n++] = protocol::MakeObjectPose(o.cam_T_model, static_cast<uint8_t>(o.model),
                                                 static_cast<uint8_t>(o.instance), score);
  }
  set->object_count = static_cast<uint8_t>(n);
  return Status::Ok();
}

}  // namespace sh::fw
