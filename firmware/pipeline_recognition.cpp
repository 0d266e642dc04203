#include "firmware/pipeline_recognition.hpp"

#include <cstdio>

#include "firmware/firmware_core.hpp"

namespace sh::fw {

namespace {

void LogToStderr(const char* line) { std::fprintf(stderr, "stereohash-fw: %s\n", line); }

ObjectRecognizerConfig OnTheBoard(ObjectRecognizerConfig config) {
  if (config.now_ns == nullptr) config.now_ns = &MonotonicNs;
  config.log = &LogToStderr;
  return config;
}

protocol::TablePlane TablePlaneOf(TableSource source) {
  switch (source) {
    case TableSource::kNone:
      return protocol::TablePlane::kNone;
    case TableSource::kGiven:
      return protocol::TablePlane::kFile;
    case TableSource::kEstimated:
      return protocol::TablePlane::kEstimated;
    case TableSource::kCarried:
      return protocol::TablePlane::kCarried;
  }
  return protocol::TablePlane::kNone;
}

}  // namespace

PipelineRecognition::PipelineRecognition(const RecognitionPathSet& paths,
                                         const ObjectRecognizerConfig& config)
    : recognizer_(paths, OnTheBoard(config)) {}

Status PipelineRecognition::Init(const StereoCalibration& calib, const ModelSet& models,
                                 uint32_t model_mask) {
  return recognizer_.Init(calib, models, model_mask);
}

Status PipelineRecognition::SetModelMask(uint32_t model_mask) {
  return recognizer_.SetModelMask(model_mask);
}

void PipelineRecognition::MapObjects(const RecognitionOutput& output, protocol::ResultSet* set) {
  size_t n = 0;
  for (const FoundObject& o : output.objects) {
    if (n == protocol::kMaxResultObjects) break;
    set->objects[n++] = protocol::MakeObjectPose(o.cam_T_model, static_cast<uint8_t>(o.model),
                                                 static_cast<uint8_t>(o.instance), o.score);
  }
  set->object_count = static_cast<uint8_t>(n);
}

Status PipelineRecognition::Process(const hal::StereoFrame& frame, float budget_ms,
                                    protocol::ResultSet* set) {
  const StereoInput pair{frame.left_frame, frame.right_frame, frame.left, frame.right};
  SH_RETURN_IF_ERROR(recognizer_.Process(pair, budget_ms, &output_));
  set->status =
      output_.budget_hit ? protocol::ResultStatus::kTimeBudgetHit : protocol::ResultStatus::kOk;
  set->table = TablePlaneOf(output_.table_source);
  if (output_.table_source != TableSource::kNone) set->left_T_table = output_.left_T_table;
  const PipelineTimings& t = output_.time;
  set->stages = {t.features_ms, t.stereo_ms, t.hashing_ms, t.verify_ms, t.refine_ms, t.total_ms};
  MapObjects(output_, set);
  return Status::Ok();
}

Status PipelineRecognition::ProcessMonocular(hal::StereoSide side, ConstGrayView image,
                                             float budget_ms, protocol::ResultSet* set) {
  const int camera = side == hal::StereoSide::kLeft ? 0 : 1;
  // Without a table plane the result set goes out empty with status 3 and an EMCY (the core).
  SH_RETURN_IF_ERROR(recognizer_.ProcessMonocular(camera, image, budget_ms, &output_));
  MapObjects(output_, set);
  set->table = TablePlaneOf(output_.table_source);
  return Status::Ok();
}

}  // namespace sh::fw
