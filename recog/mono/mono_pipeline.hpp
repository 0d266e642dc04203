// Recognition from one camera's image: features of that image, then the monocular recogniser
// (thesis ch. 6 with a pose per object). The image may come from either camera of the stereo
// pair; poses are reported in the left camera's frame as by the stereo pipeline. Statically
// allocated apart from the feature workspace, which the owner lends (the stereo pipeline has
// one per camera); Process() does not touch the heap.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/image/features.hpp"
#include "recog/mono/mono_recognizer.hpp"
#include "tables/aspect_view.hpp"

namespace sh {

// Why the products' one-camera modes refuse to run without a table plane: from one image a
// model's size fits it at any depth (a small part near, a large one far), so the poses would be
// guesses. With the plane, an object rests on it and its depth follows. The recogniser itself
// still runs without a table (free 6-D poses, for studies and the stereo rescue, which confirms
// depth in the other image).
inline constexpr char kMonoNeedsTablePlane[] =
    "one camera cannot tell an object's depth without the table plane (a model's size fits it at "
    "many depths)";

struct MonoPipelineConfig {
  FeatureConfig features = FeatureConfig::LightBackground();
  MonoConfig mono;

  // Presets for the two kinds of scene: the corner scale of 2 px (as the stereo presets; the
  // corners at line junctions make up for those it misses) and Canny at 1 px on the dark
  // table, 1.25 px on the light one (lower-contrast objects on their own shadows: the edges
  // verification needs survive the smaller scale better than 1.5 px).
  static MonoPipelineConfig DarkBackground();
  static MonoPipelineConfig LightBackground();
  // The default: detector thresholds measured from each image (FeatureConfig::adaptive, as the
  // stereo pipeline's automatic configuration) with the light preset's Canny scale.
  static MonoPipelineConfig Automatic();
};

// Milliseconds; zero without a clock.
struct MonoTimings {
  float features_ms = 0, recognition_ms = 0, total_ms = 0;
};

struct MonoResult {
  Vector<RecognizedObject, kMaxObjects> objects;  // left-camera frame
  uint32_t points2d = 0, lines2d = 0;             // detected corners and lines of the image
  uint32_t junction_corners = 0;                  // corners added at line junctions
  MonoStats stats;
  MonoTimings time;
};

class MonoPipeline {
 public:
  using ClockFn = int64_t (*)();

  // `camera`: 0 for the left image, 1 for the right. `left_T_table`: the table pose in the left
  // camera frame (objects rest on it), or null for free 6-D poses.
  Status Init(const StereoCalibration& calib, int camera, const AspectTableView& table,
              const RigidTransform* left_T_table, const MonoPipelineConfig& config,
              ClockFn now_ns = nullptr);
  bool initialised() const { return initialised_; }
  int camera() const { return camera_; }
  const MonoPipelineConfig& config() const { return config_; }

  // Recognises the objects in one image of that camera (its size must match the calibration),
  // with `workspace` for the feature extraction. budget_ms <= 0: no time limit.
  Status Process(ConstGrayView image, float budget_ms, FeatureWorkspace& workspace,
                 MonoResult* out);

  const ImageFeatures& features() const { return features_; }
  const MonoRecognizer& recognizer() const { return recognizer_; }
  MonoRecognizer& recognizer() { return recognizer_; }
  const CameraIntrinsics& intrinsics() const { return view_.intrinsics; }
  const ViewCamera& view() const { return view_; }

 private:
  float MsSince(int64_t start_ns) const;

  bool initialised_ = false;
  int camera_ = 0;
  ViewCamera view_;
  MonoPipelineConfig config_;
  ClockFn now_ns_ = nullptr;
  ImageFeatures features_;
  MonoRecognizer recognizer_;
};

}  // namespace sh
