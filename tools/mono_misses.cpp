#include "tools/mono_misses.hpp"

#include <cstdio>

namespace sh::tools {

namespace {

// Each cause's JSON key and its words in the --verbose lines.
struct MissCause {
  const char* key;
  const char* words;
};
constexpr MissCause kMissCauses[3] = {{"no_features", "features missing"},
                                      {"no_edges", "edges fail verification"},
                                      {"not_searched", "not found by the search"}};

}  // namespace

const char* MonoMissCauseKey(int cause) {
  return cause >= 0 && cause < 3 ? kMissCauses[cause].key : "unknown";
}

void ExplainMonoMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                       const Vector<RecognizedObject>& found, const ImageFeatures& features,
                       MonoRecognizer& recognizer, const char* label, bool verbose, int causes[3],
                       float max_t_mm, float max_r_deg, std::vector<MonoMiss>* misses) {
  std::vector<RecognizedPose> poses;
  for (const RecognizedObject& o : found) poses.push_back({o.model, o.cam_T_model});
  const MatchCounts m = MatchToTruth(models, truth, poses, max_t_mm, max_r_deg);
  for (size_t t = 0; t < truth.size(); ++t) {
    if (m.truth_found[t]) continue;
    MonoDiagnosis d;
    if (!recognizer.Diagnose(features, truth[t].model, truth[t].cam_T_model, &d).ok()) continue;
    const int shown = d.corners_visible + d.pieces_visible;
    const int detected = d.corners_detected + d.pieces_detected;
    const int cause = 2 * detected < shown                                          ? 0
                      : d.verify_fraction < recognizer.config().verify.min_fraction ? 1
                                                                                    : 2;
    ++causes[cause];
    if (misses != nullptr) misses->push_back({t, cause, d});
    if (verbose) {
      std::printf(
          "  %s: missed %s: %s (corners %d of %d, edge pieces %d of %d, edges confirmed %.2f, "
          "%d scene bases on it, %d of them find it)\n",
          label, models[truth[t].model].name, kMissCauses[cause].words, d.corners_detected,
          d.corners_visible, d.pieces_detected, d.pieces_visible, d.verify_fraction, d.object_bases,
          d.bases_found);
    }
  }
}

}  // namespace sh::tools
