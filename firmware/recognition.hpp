// What the firmware core needs from recognition: one call per captured pair (or, when one camera
// has failed, per frame of the other) that fills the poses of a result set. Behind an interface so
// that the board runs the real pipeline (pipeline_recognition) while the simulator can also report
// its ground truth, and the fault tests can use a double.
#pragma once

#include <cstdint>

#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"
#include "hal/camera.hpp"
#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/pipeline/model_set.hpp"

namespace sh::fw {

class Recognition {
 public:
  virtual ~Recognition() = default;

  // Called at boot and after a cleared data fault, before any Process(). May allocate. The
  // model set (hash tables, then the feature database's printed models) stays valid until the
  // next Init().
  virtual Status Init(const StereoCalibration& calib, const ModelSet& models,
                      uint32_t model_mask) = 0;
  // Restricts recognition to the models whose bits are set (already range-checked).
  virtual Status SetModelMask(uint32_t model_mask) = 0;
  // Fills set->objects, set->object_count and set->status (kOk or kTimeBudgetHit). A non-ok
  // Status means no result (the core reports kInternalError with an EMCY). Must not allocate.
  virtual Status Process(const hal::StereoFrame& frame, float budget_ms,
                         protocol::ResultSet* set) = 0;

  // Whether ProcessMonocular works: the core falls back to one camera only then, and otherwise
  // stays in fault when a camera fails.
  virtual bool monocular() const { return false; }
  // One camera's frame (`side`; the other camera failed): fills set->objects and object_count
  // with poses in the left camera frame, as Process does; the core sets the monocular status.
  // Must not allocate.
  virtual Status ProcessMonocular(hal::StereoSide side, ConstGrayView image, float budget_ms,
                                  protocol::ResultSet* set) {
    return Status::Error(StatusCode::kUnimplemented, "no monocular recognition");
  }
};

}  // namespace sh::fw
