#include "tools/bench_scoring.hpp"

#include <cstdio>
#include <utility>

#include "tools/report_util.hpp"

namespace sh::tools {

void ScoreRow::Add(const ScoreRow& other) {
  scenes += other.scenes;
  objects += other.objects;
  correct += other.correct;
  missed += other.missed;
  false_alarms += other.false_alarms;
  failed += other.failed;
  scene_bases_tried += other.scene_bases_tried;
  for (auto [dst, src] : {std::pair{&time_ms, &other.time_ms},
                          {&points2d, &other.points2d},
                          {&lines2d, &other.lines2d},
                          {&points3d, &other.points3d},
                          {&lines3d, &other.lines3d},
                          {&t_err_mm, &other.t_err_mm},
                          {&r_err_deg, &other.r_err_deg},
                          {&feature_t_err_mm, &other.feature_t_err_mm},
                          {&feature_r_err_deg, &other.feature_r_err_deg},
                          {&features_ms, &other.features_ms},
                          {&stereo_ms, &other.stereo_ms},
                          {&hashing_ms, &other.hashing_ms},
                          {&verify_ms, &other.verify_ms}}) {
    dst->insert(dst->end(), src->begin(), src->end());
  }
}

void ScoreRow::AddMatch(const MatchCounts& match, size_t truth_objects) {
  ++scenes;
  objects += static_cast<int>(truth_objects);
  correct += match.correct;
  missed += match.missed;
  false_alarms += match.false_alarms;
  t_err_mm.insert(t_err_mm.end(), match.translation_errors_mm.begin(),
                  match.translation_errors_mm.end());
  r_err_deg.insert(r_err_deg.end(), match.rotation_errors_deg.begin(),
                   match.rotation_errors_deg.end());
}

void ScoreRow::AddStereoFrame(const PipelineResult& result) {
  time_ms.push_back(result.time.total_ms);
  features_ms.push_back(result.time.features_ms);
  stereo_ms.push_back(result.time.stereo_ms);
  hashing_ms.push_back(result.time.hashing_ms);
  verify_ms.push_back(result.time.verify_ms);
  scene_bases_tried += result.recognition.scene_bases_tried;
  points2d.push_back(float(result.points2d[0] + result.points2d[1]) * 0.5f);
  lines2d.push_back(float(result.lines2d[0] + result.lines2d[1]) * 0.5f);
  points3d.push_back(float(result.points3d));
  lines3d.push_back(float(result.lines3d));
}

void ScoreRow::AddMonoFrame(const MonoResult& result) {
  time_ms.push_back(result.time.total_ms);
  features_ms.push_back(result.time.features_ms);
  hashing_ms.push_back(result.time.recognition_ms);
  points2d.push_back(float(result.points2d));
  lines2d.push_back(float(result.lines2d));
}

void PrintScoreHeader() {
  std::printf("%-6s %-7s %6s %7s %7s %6s %6s %8s %8s %6s %6s %6s %6s %7s %7s\n", "backgr", "occlus",
              "scenes", "objects", "correct", "missed", "false", "med ms", "worst ms", "2D pts",
              "2D lin", "3D pts", "3D lin", "t mm", "R deg");
}

void PrintScoreRow(const ScoreRow& row) {
  std::printf("%-6s %-7s %6d %7d %7d %6d %6d %8.1f %8.1f %6.0f %6.0f %6.0f %6.0f %7.2f %7.2f\n",
              row.background.c_str(), row.occlusion.c_str(), row.scenes, row.objects, row.correct,
              row.missed, row.false_alarms, Median(row.time_ms), Max(row.time_ms),
              Median(row.points2d), Median(row.lines2d), Median(row.points3d), Median(row.lines3d),
              Median(row.t_err_mm), Median(row.r_err_deg));
}

std::string ScoreRowJson(const ScoreRow& row, bool with_failed) {
  char failed[32] = "";
  if (with_failed) std::snprintf(failed, sizeof(failed), "\"failed\": %d, ", row.failed);
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "{\"background\": \"%s\", \"occlusion\": \"%s\", \"scenes\": %d, \"objects\": %d, "
                "\"correct\": %d, \"missed\": %d, \"false_alarms\": %d, %s\"median_ms\": %.2f, "
                "\"worst_ms\": %.2f, \"median_stage_ms\": {\"features\": %.2f, \"stereo\": %.2f, "
                "\"hashing\": %.2f, \"verify\": %.2f}, \"points2d\": %.0f, \"lines2d\": %.0f, "
                "\"points3d\": %.0f, \"lines3d\": %.0f, \"median_t_err_mm\": %.3f, "
                "\"median_r_err_deg\": %.3f}",
                row.background.c_str(), row.occlusion.c_str(), row.scenes, row.objects, row.correct,
                row.missed, row.false_alarms, failed, Median(row.time_ms), Max(row.time_ms),
                Median(row.features_ms), Median(row.stereo_ms), Median(row.hashing_ms),
                Median(row.verify_ms), Median(row.points2d), Median(row.lines2d),
                Median(row.points3d), Median(row.lines3d), Median(row.t_err_mm),
                Median(row.r_err_deg));
  return buffer;
}

double Percent(int part, int whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

void RescueTally::Add(const PipelineResult& result) {
  ran += result.rescue.ran ? 1 : 0;
  added += static_cast<int>(result.rescue.added);
  ms.push_back(result.time.rescue_ms);
}

void RescueTally::Print(size_t scenes) const {
  std::printf(
      "rescue (one image, confirmed in both): ran in %d of %zu scenes, added %d "
      "objects; %.1f ms median, %.1f ms worst\n",
      ran, scenes, added, Median(ms), Max(ms));
}

void MissTally::Print(bool monocular, const ScoreRow& total) const {
  if (monocular) {
    std::printf(
        "missed %d: at the true pose %d show under half of their corners and edges in the "
        "image's features, %d fail the image verification, %d were not found by the search\n",
        total.missed, mono[0], mono[1], mono[2]);
    return;
  }
  std::printf(
      "missed %d: at the true pose %d fail the image verification (edges too weak or hidden), "
      "%d have under 30 %% 3-D support (stereo lost them), %d were not reached by the search\n",
      total.missed, stereo.no_edges, stereo.no_3d, stereo.not_searched);
  std::printf("scene bases tried %ld over %d scenes\n", total.scene_bases_tried, total.scenes);
}

std::string MissTally::Json(bool monocular) const {
  if (monocular) {
    return "{\"no_features\": " + std::to_string(mono[0]) +
           ", \"no_edges\": " + std::to_string(mono[1]) +
           ", \"not_found\": " + std::to_string(mono[2]) + "}";
  }
  return "{\"no_edges\": " + std::to_string(stereo.no_edges) +
         ", \"no_3d\": " + std::to_string(stereo.no_3d) +
         ", \"not_searched\": " + std::to_string(stereo.not_searched) + "}";
}

}  // namespace sh::tools
