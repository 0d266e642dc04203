// Why the monocular mode missed objects, for the `bench` commands.
#pragma once

#include <vector>

#include "recog/mono/mono_recognizer.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh::tools {

// One object the monocular mode missed: which truth object, why (0-2, as counted by
// ExplainMonoMisses) and what the recogniser's diagnosis found at its true pose.
struct MonoMiss {
  size_t truth_index = 0;
  int cause = 0;
  MonoDiagnosis diagnosis;
};

// The cause's key in the benches' JSON: "no_features", "no_edges" or "not_searched".
const char* MonoMissCauseKey(int cause);

// Why the monocular mode missed objects, judged at their true poses (Diagnose): causes[0] the
// image's features hold under half of the corners and edge pieces the model shows there,
// causes[1] the edge-pixel verification rejects even the true pose, causes[2] neither (the
// search did not find it). `verbose` prints one line per miss, starting with `label`; each miss
// is appended to `misses` when given.
void ExplainMonoMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                       const Vector<RecognizedObject>& found, const ImageFeatures& features,
                       MonoRecognizer& recognizer, const char* label, bool verbose, int causes[3],
                       float max_t_mm, float max_r_deg, std::vector<MonoMiss>* misses = nullptr);

}  // namespace sh::tools
