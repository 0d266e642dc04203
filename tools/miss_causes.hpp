// Why objects were missed, judged at their true poses: does the image verification accept the
// true pose (are the edges there), and how much 3-D support does the scene hold there (did
// stereo produce the object's corners and lines)? Used by the `bench` commands.
#pragma once

#include <vector>

#include "recog/model/model.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh::tools {

// Every hypothesis and acceptance of one frame's search (Pipeline::SetSearchObserver), for
// ExplainMisses. Clear() before each frame.
class SearchTrace : public SearchObserver {
 public:
  struct Step {
    uint32_t basis_number = 0;
    Hypothesis hypothesis;
    RecognizedObject candidate;
    Outcome outcome = Outcome::kRejected;
  };
  void Clear() {
    steps.clear();
    accepted.clear();
  }
  void OnHypothesis(uint32_t basis_number, const Hypothesis& h, const RecognizedObject& candidate,
                    Outcome outcome) override {
    steps.push_back({basis_number, h, candidate, outcome});
  }
  void OnAccepted(uint32_t basis_number, const RecognizedObject& object) override {
    accepted.push_back({basis_number, object});
  }

  std::vector<Step> steps;
  std::vector<std::pair<uint32_t, RecognizedObject>> accepted;
};

struct MissCauses {
  int no_edges = 0;      // the verifier rejects even the true pose
  int no_3d = 0;         // verifiable, but under 30 % of the model's features in the 3-D scene
  int not_searched = 0;  // verifiable and supported: the search did not reach it
};

// One missed truth object and what was found at its true pose.
struct MissRecord {
  size_t truth_index = 0;
  const char* cause = "";  // "no_edges", "no_3d" or "not_searched"
  float verify_score[2] = {0.0f, 0.0f};
  float support = 0.0f;  // fraction of the model's corners and edges in the 3-D scene
  // Where the object's features were lost: model edges (corners) visible in both images, of
  // them found as a 2-D line (corner) in the left and in the right image, and as a 3-D line
  // (point) of the scene.
  int edges_visible = 0, edges_2d[2] = {0, 0}, edges_3d = 0;
  int corners_visible = 0, corners_2d[2] = {0, 0}, corners_3d = 0;
  // Edges found as 2-D lines in both images; of them, those without a 3-D line, and of those the
  // ones whose interpretation planes meet at less than the stereo's min_plane_angle_deg (near
  // the epipolar direction: line stereo rejects such pairs as degenerate).
  int edges_2d_both = 0, edges_lost_stereo = 0, edges_lost_epipolar = 0;
  // The search's view (line + point hash functions, with a Recognizer given): scene bases of the
  // first candidate pass whose line and point both lie on the object, the rank of the first one,
  // and how many of them vote the true model near its pose above the threshold (and the rank of
  // the first such basis). Ranks are in the frame's initial order; -1: none.
  int own_bases = 0, first_own_rank = -1, good_bases = 0, first_good_rank = -1;
  int candidates = 0;
  // What the search did with hypotheses of the true model whose voted pose was within 10 mm /
  // 10 deg of the truth (with a SearchTrace): how many, how many refinement kept within 5 mm /
  // 5 deg, and their outcomes; the best verify scores; and when one verified but another
  // hypothesis of its scene basis was accepted, that one's model.
  int near_hypotheses = 0, refined_close = 0, too_close = 0, rejected = 0, verified = 0;
  float best_verify[2] = {0.0f, 0.0f};
  const char* lost_to = "";
};

// For every truth object that `result` missed (matching within max_t_mm / max_r_deg), adds its
// cause to `causes` (and a record to `records` when given); `verbose` prints one line per miss,
// starting with `label` (scene name). With `search` (a Recognizer initialised with the
// pipeline's table and recogniser settings; its state is overwritten) each miss also gets the
// search's view of its scene bases.
void ExplainMisses(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                   const PipelineResult& result, const Pipeline& pipeline, const char* label,
                   bool verbose, MissCauses* causes, float max_t_mm = 10.0f,
                   float max_r_deg = 10.0f, std::vector<MissRecord>* records = nullptr,
                   Recognizer* search = nullptr, const SearchTrace* trace = nullptr);

}  // namespace sh::tools
