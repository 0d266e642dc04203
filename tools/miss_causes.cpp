#include "tools/miss_causes.hpp"

#include <cstdio>

#include "recog/verify/verify.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/eval/truth_pose_fit.hpp"

namespace sh::tools {

void ExplainMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                   const PipelineResult& result, const Pipeline& pipeline, const char* label,
                   bool verbose, MissCauses* causes, float max_t_mm, float max_r_deg) {
  const std::vector<RecognizedPose> found = PosesOf(result);
  const MatchCounts matched = MatchToTruth(models, truth, found, max_t_mm, max_r_deg);
  for (size_t i = 0; i < truth.size(); ++i) {
    if (matched.truth_found[i]) continue;
    const Model& model = models[truth[i].model];
    PosedModel occluders[kMaxOccluders];
    size_t n_occluders = 0;
    for (size_t j = 0; j < truth.size() && n_occluders < kMaxOccluders; ++j) {
      if (j != i) occluders[n_occluders++] = {&models[truth[j].model], truth[j].cam_T_model};
    }
    const ConstEdgeMapView left{pipeline.left_features().edges.edge,
                                pipeline.left_features().edges.orientation};
    const ConstEdgeMapView right{pipeline.right_features().edges.edge,
                                 pipeline.right_features().edges.orientation};
    const Result<VerifyResult> v =
        VerifyHypothesis(pipeline.calibration(), left, right, {&model, truth[i].cam_T_model},
                         occluders, n_occluders, pipeline.config().verify);
    const TruthPoseFit fit = FitFromTruePose(model, truth[i].cam_T_model, pipeline.scene(),
                                             pipeline.config().recognizer);
    const bool verifiable = v.ok() && v->accepted;
    if (!verifiable) {
      ++causes->no_edges;
    } else if (fit.support < 0.3f) {
      ++causes->no_3d;
    } else {
      ++causes->not_searched;
    }
    if (verbose) {
      std::printf(
          "  %s: missed %s; at its true pose: image verification %.2f %.2f (%s), 3-D "
          "support %.2f (%d corners, %d edges)\n",
          label, model.name, v.ok() ? v->score_left : 0.0f, v.ok() ? v->score_right : 0.0f,
          verifiable ? "accepted" : "rejected", fit.support, fit.matched_points, fit.matched_lines);
    }
  }
}

}  // namespace sh::tools
