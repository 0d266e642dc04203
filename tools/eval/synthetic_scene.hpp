// Synthetic 3-D scenes with ground truth, for recognition tests and benchmarks.
//
// Reference objects at random poses inside a working volume, their corners and edges with
// feature noise, a fraction of them missing, plus clutter: spurious points and lines uniform in
// the volume and structured clutter that real stereo produces (fragments of model outlines, as
// shadows and reflections give, and false stereo matches displaced in depth along the viewing
// ray, which share their left-image feature with a real one).
#pragma once

#include <cstdint>
#include <vector>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

struct SyntheticSceneParams {
  int min_objects = 1, max_objects = 5;
  float noise_min_mm = 0.5f, noise_max_mm = 1.0f;  // per-scene noise sigma drawn in this range
  float missing_min = 0.2f, missing_max = 0.4f;    // fraction of object features dropped
  int total_features = 500;                        // objects + clutter, points and lines
  float structured_fraction = 0.3f;                // of the clutter
  Eigen::Vector3f volume_min_mm{-200.0f, -200.0f, 500.0f};  // 400 x 400 x 70 mm in front of
  Eigen::Vector3f volume_max_mm{200.0f, 200.0f, 570.0f};    // the camera
  uint32_t model_mask = 0xffffffffu;
};

struct TruthObject {
  int model = 0;
  RigidTransform cam_T_model;
};

struct SyntheticScene {
  Scene scene;
  std::vector<TruthObject> truth;
};

// Deterministic for a given seed (own PRNG, no library distributions).
void GenerateSyntheticScene(const std::vector<Model>& models, const SyntheticSceneParams& params,
                            uint64_t seed, SyntheticScene* out);

// Rotation error in degrees between two poses of a model, minimised over its symmetry group.
float SymmetricRotationErrorDeg(const Model& model, const Eigen::Matrix3f& R_estimate,
                                const Eigen::Matrix3f& R_truth);

struct MatchCounts {
  int correct = 0, missed = 0, false_alarms = 0;
  std::vector<float> translation_errors_mm, rotation_errors_deg;
  std::vector<bool> truth_found;  // per truth object: matched by a recognised one
};

// Matches recognised objects to the truth: same model, centre within max_translation_mm and
// rotation within max_rotation_deg (symmetry-aware); each truth object matches once.
struct RecognizedPose {
  int model = -1;
  RigidTransform cam_T_model;
};
MatchCounts MatchToTruth(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                         const std::vector<RecognizedPose>& found, float max_translation_mm = 10.0f,
                         float max_rotation_deg = 10.0f);

}  // namespace sh
