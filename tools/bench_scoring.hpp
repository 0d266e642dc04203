// What `bench recorded` and `bench scenes` report alike once recognised poses are matched to the
// truth: one row per background x occlusion (thesis table 5.5), the row's medians and its JSON,
// the one-image rescue's figures and why the missed objects were missed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/miss_causes.hpp"

namespace sh::tools {

// The figures of one background x occlusion over its scenes; counts summed, per-scene values
// kept for their medians.
struct ScoreRow {
  std::string background, occlusion;
  int scenes = 0, objects = 0, correct = 0, missed = 0, false_alarms = 0;
  int failed = 0;              // scenes the pipeline returned an error for (bench scenes)
  long scene_bases_tried = 0;  // summed over the scenes: the search's cost, machine-independent
  std::vector<float> time_ms, points2d, lines2d, points3d, lines3d, t_err_mm, r_err_deg;
  // Errors of the same correct objects before the final fit to the image edges (bench recorded).
  std::vector<float> feature_t_err_mm, feature_r_err_deg;
  std::vector<float> features_ms, stereo_ms, hashing_ms, verify_ms;

  // Another row's scenes into this one (the total).
  void Add(const ScoreRow& other);
  // One scene of `truth_objects` objects matched to the truth: its counts and pose errors.
  void AddMatch(const MatchCounts& match, size_t truth_objects);
  // A stereo frame's stage times and feature counts (2-D counts: mean of left and right).
  void AddStereoFrame(const PipelineResult& result);
  // A monocular frame's: recognition counts as the stage "hashing"; no stereo, no 3-D counts.
  void AddMonoFrame(const MonoResult& result);
};

// The column heads of PrintScoreRow.
void PrintScoreHeader();
// One row of the table: counts, median and worst frame time, median feature counts and errors.
void PrintScoreRow(const ScoreRow& row);
// The row as JSON ({"background": ..., "median_t_err_mm": ...}); `with_failed` adds "failed".
std::string ScoreRowJson(const ScoreRow& row, bool with_failed);

// 100 * part / whole, 0 for an empty whole.
double Percent(int part, int whole);

// The one-image rescue over the scenes: frames it ran in, objects it added, its time per frame.
struct RescueTally {
  int ran = 0, added = 0;
  std::vector<float> ms;

  void Add(const PipelineResult& result);
  // "rescue (one image, confirmed in both): ran in R of N scenes, ..."
  void Print(size_t scenes) const;
};

// Why objects were missed: the stereo pipeline's causes (ExplainMisses) or the monocular mode's
// (ExplainMonoMisses: no features, no edges, not found).
struct MissTally {
  MissCauses stereo;
  int mono[3] = {};

  // "missed N: at the true pose ..." for the mode that ran; for the stereo pipeline also the
  // scene bases the search tried.
  void Print(bool monocular, const ScoreRow& total) const;
  // {"no_edges": ..., "no_3d": ..., "not_searched": ...} or the monocular causes.
  std::string Json(bool monocular) const;
};

}  // namespace sh::tools
