// The board's recogniser: the recognition facade (recog/pipeline/object_recognizer.hpp), which
// runs every path a frame can take, with its neutral result mapped to the CAN result set. The
// facade's notes on the cell (table plane, rescue) go to stderr, the board's log.
#pragma once

#include <cstdint>

#include "firmware/recognition.hpp"
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/recognition_paths.hpp"

namespace sh::fw {

class PipelineRecognition final : public Recognition {
 public:
  // `paths`: the facade's paths (RecognitionPaths), owned by the caller and outliving this. The
  // facade's clock is the firmware's monotonic one unless `config` names another (a simulation's
  // clock), and its log the board's.
  PipelineRecognition(const RecognitionPathSet& paths, const ObjectRecognizerConfig& config);

  Status Init(const StereoCalibration& calib, const ModelSet& models, uint32_t model_mask) override;
  Status SetModelMask(uint32_t model_mask) override;
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;
  bool monocular() const override { return recognizer_.monocular(); }
  Status ProcessMonocular(hal::StereoSide side, ConstGrayView image, float budget_ms,
                          protocol::ResultSet* set) override;

  const ObjectRecognizer& recognizer() const { return recognizer_; }

 private:
  // The facade's objects into the result set, up to its capacity (the rest is not reported).
  static void MapObjects(const RecognitionOutput& output, protocol::ResultSet* set);

  ObjectRecognizer recognizer_;
  RecognitionOutput output_;
};

}  // namespace sh::fw
