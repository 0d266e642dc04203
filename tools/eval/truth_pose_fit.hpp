// The best a recogniser can do on one synthetic object: the support the verifier would count
// at the true pose, and where pose refinement converges when started from the true pose. Tells
// apart what the search misses from what the data no longer shows (features dropped, noise
// beyond the gate) and gives the pose-error floor the noise sets.
#pragma once

#include "recog/geometry/rigid_transform.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/model/model.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

struct TruthPoseFit {
  int matched_points = 0;  // within the verifier's gate, at the refined pose
  int matched_lines = 0;
  float support = 0.0f;    // mean of the corner and edge fractions, as SceneSupportVerifier scores
  float t_err_mm = 0.0f;   // refined pose against the truth
  float r_err_deg = 0.0f;  // symmetry-aware
};

// All scene features count as available. Not thread-safe (static scratch).
TruthPoseFit FitFromTruePose(const Model& model, const RigidTransform& true_cam_T_model,
                             const Scene& scene, const RecognizerConfig& config);

}  // namespace sh
