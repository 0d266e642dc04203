// Verification of a printed model's pose in both images: the print must be where the pose puts
// it. Every visible printed face is sampled on a grid of its stored texture; each sample is
// projected into the left and the right image (distortion kept), and the samples hidden by the
// objects already accepted (convex models ray-cast in their poses) or outside the image are
// left out. Per image, the score is the zero-mean normalised cross-correlation between texture
// and image over each face (faces are lit differently), averaged over the faces weighted by
// their area in the image (samples times the cosine of the viewing angle).
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/image.hpp"
#include "recog/model/model.hpp"
#include "tables/feature_db_view.hpp"

namespace sh::texture {

// Occluders considered per score (the nearest first is the caller's choice); more are ignored.
inline constexpr size_t kMaxPrintOccluders = 32;

struct PrintVerifyConfig {
  float min_zncc = 0.5f;         // in each image
  int sample_step_texels = 2;    // grid spacing on the stored texture
  int min_samples = 100;         // visible samples per image
  int min_face_samples = 30;     // a face with fewer visible samples is not scored
  float min_texture_std = 4.0f;  // grey levels: flatter faces carry no evidence
  float min_view_cosine = 0.2f;  // faces seen more obliquely (78 degrees) are not scored
};

struct PrintScore {
  float zncc[2] = {0, 0};        // left, right
  uint32_t samples[2] = {0, 0};  // scored samples
  uint32_t faces[2] = {0, 0};    // scored faces
  uint32_t hidden[2] = {0, 0};   // samples hidden by accepted objects
};

// A model already accepted in this frame, as an occluder.
struct PlacedModel {
  const Model* model = nullptr;
  RigidTransform cam_T_model;
};

class PrintVerifier {
 public:
  void Reset(const StereoCalibration* calib, const FeatureDbView* db, ConstGrayView left,
             ConstGrayView right);

  PrintScore Score(uint32_t model, const RigidTransform& cam_T_model, const PlacedModel* occluders,
                   size_t n_occluders, const PrintVerifyConfig& config) const;

  static bool Accept(const PrintScore& score, const PrintVerifyConfig& config) {
    for (int i = 0; i < 2; ++i) {
      if (score.samples[i] < static_cast<uint32_t>(config.min_samples) ||
          score.zncc[i] < config.min_zncc)
        return false;
    }
    return true;
  }

 private:
  const StereoCalibration* calib_ = nullptr;
  const FeatureDbView* db_ = nullptr;
  ConstGrayView images_[2]{};
};

// Whether the segment from `origin` to `target` (camera frame) passes through the convex model
// placed at cam_T_model before reaching within `margin_mm` of the target.
bool SegmentHitsConvexModel(const Model& model, const RigidTransform& cam_T_model,
                            const Eigen::Vector3f& origin, const Eigen::Vector3f& target,
                            float margin_mm);

}  // namespace sh::texture
