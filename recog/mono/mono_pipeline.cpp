#include "recog/mono/mono_pipeline.hpp"

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/image_check.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

MonoPipelineConfig MonoPipelineConfig::DarkBackground() {
  MonoPipelineConfig c;
  c.features.canny = FeatureConfig::DarkBackground().canny;
  return c;
}

MonoPipelineConfig MonoPipelineConfig::LightBackground() {
  MonoPipelineConfig c;
  c.features.canny.sigma_px = 1.25f;
  return c;
}

MonoPipelineConfig MonoPipelineConfig::Automatic() {
  MonoPipelineConfig c = LightBackground();
  // The stereo pipeline's detection (FeatureConfig::Automatic: corners at four noise sigmas of
  // contrast, 20 grey levels at least, thresholds raised over texture) at this preset's Canny
  // scale. Edges at 4.5 gradient-noise sigmas, not 3.5: one image has no second view to refuse
  // an outline fitted to noise edges, and over sixteen polyhedral sets 3.5 found 12 objects
  // more with 6 false alarms more.
  const float canny_sigma_px = c.features.canny.sigma_px;
  c.features = FeatureConfig::Automatic();
  c.features.canny.sigma_px = canny_sigma_px;
  c.features.edge_snr = 4.5f;
  return c;
}

Status MonoPipeline::Init(const StereoCalibration& calib, int camera, const AspectTableView& table,
                          const RigidTransform* left_T_table, const MonoPipelineConfig& config,
                          ClockFn now_ns) {
  initialised_ = false;
  if (camera != 0 && camera != 1) {
    return Status::Error(StatusCode::kInvalidArgument, "mono pipeline: camera %d is not 0 or 1",
                         camera);
  }
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
  const ViewCamera view = camera == 0 ? LeftView(calib) : RightView(calib);
  if (view.intrinsics.width > kMaxImageWidth || view.intrinsics.height > kMaxImageHeight) {
    return Status::Error(
        StatusCode::kOutOfRange, "mono pipeline: image size %dx%d exceeds the supported %dx%d",
        view.intrinsics.width, view.intrinsics.height, kMaxImageWidth, kMaxImageHeight);
  }
  SH_RETURN_IF_ERROR(ValidateFeatureConfig(config.features));
  SH_RETURN_IF_ERROR(recognizer_.Init(view, table, left_T_table, config.mono));
  camera_ = camera;
  view_ = view;
  config_ = config;
  now_ns_ = now_ns;
  initialised_ = true;
  return Status::Ok();
}

float MonoPipeline::MsSince(int64_t start_ns) const {
  // Nanoseconds to milliseconds; frame times fit a float's 24 bits many times over.
  return now_ns_ ? static_cast<float>(now_ns_() - start_ns) * 1e-6f : 0.0f;
}

Status MonoPipeline::Process(ConstGrayView image, float budget_ms, FeatureWorkspace& workspace,
                             MonoResult* out) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "mono: no result");
  out->objects.clear();
  *out = MonoResult{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "mono pipeline: Init() has not succeeded");
  }
  const CameraIntrinsics& cam = view_.intrinsics;
  const char* which = camera_ == 0 ? "left" : "right";
  SH_RETURN_IF_ERROR(CheckImageFitsCamera(image, cam, which));
  const int64_t t0 = now_ns_ ? now_ns_() : 0;
  const Status s = ExtractFeatures(image, config_.features, workspace, features_);
  if (!s.ok()) return Status::Error(s.code(), "%s image: %s", which, s.message());
  out->points2d = static_cast<uint32_t>(features_.corners.size());
  out->lines2d = static_cast<uint32_t>(features_.lines.size());
  const int64_t t1 = now_ns_ ? now_ns_() : 0;
  out->time.features_ms = MsSince(t0);
  Budget budget;
  if (budget_ms > 0 && now_ns_ != nullptr) {
    // The budget covers the whole frame: recognition gets what the features left over.
    budget.deadline_ns = t0 + static_cast<int64_t>(static_cast<double>(budget_ms) * 1e6);
    budget.now_ns = now_ns_;
  }
  SH_RETURN_IF_ERROR(recognizer_.Recognize(features_, budget, out->objects, &out->stats));
  out->junction_corners = static_cast<uint32_t>(recognizer_.junction_corner_count());
  if (now_ns_) {
    out->time.recognition_ms = MsSince(t1);
    out->time.total_ms = MsSince(t0);
  }
  return Status::Ok();
}

}  // namespace sh
