// Why objects were missed, judged at their true poses: does the image verification accept the
// true pose (are the edges there), and how much 3-D support does the scene hold there (did
// stereo produce the object's corners and lines)? Used by the `bench` commands.
#pragma once

#include <vector>

#include "recog/model/model.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh::tools {

struct MissCauses {
  int no_edges = 0;      // the verifier rejects even the true pose
  int no_3d = 0;         // verifiable, but under 30 % of the model's features in the 3-D scene
  int not_searched = 0;  // verifiable and supported: the search did not reach it
};

// For every truth object that `result` missed (matching within max_t_mm / max_r_deg), adds its
// cause to `causes`; `verbose` prints one line per miss, starting with `label` (scene name).
void ExplainMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                   const PipelineResult& result, const Pipeline& pipeline, const char* label,
                   bool verbose, MissCauses* causes, float max_t_mm = 10.0f,
                   float max_r_deg = 10.0f);

}  // namespace sh::tools
