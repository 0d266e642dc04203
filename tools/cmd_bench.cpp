// `stereohash bench scenes|synthetic`: the thesis's evaluation grids, measured on this machine.
//
// scenes:    rendered stereo pairs through the whole pipeline, one row per background x
//            occlusion (thesis table 5.4), reported like table 5.5.
// synthetic: the recogniser alone on synthetic 3-D scenes, for all five hash functions, and the
//            time per scene against the number of scene features.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "hal/sim/world/scene_generator.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/verify.hpp"
#include "tables/model_files.hpp"
#include "tables/table_builder.hpp"
#include "tables/table_file.hpp"
#include "tools/bench_recorded.hpp"
#include "tools/bench_textured.hpp"
#include "tools/command.hpp"
#include "tools/cv_program.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/eval/truth_pose_fit.hpp"
#include "tools/miss_causes.hpp"
#include "tools/mono_misses.hpp"
#include "tools/mono_setup.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool ParseInt(const char* text, int lo, int hi, int* value) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || v < lo || v > hi) return false;
  *value = static_cast<int>(v);
  return true;
}

// ---------------------------------------------------------------------------------------------
// bench scenes

struct SceneRow {
  SceneRow(const char* b, const char* o, render::Background bg_, render::Occlusion occ_)
      : background(b), occlusion(o), bg(bg_), occ(occ_) {}
  const char* background;
  const char* occlusion;
  render::Background bg;
  render::Occlusion occ;
  int scenes = 0, objects = 0, correct = 0, missed = 0, false_alarms = 0, failed = 0;
  long scene_bases_tried = 0;  // summed over the scenes: the search's cost, machine-independent
  std::vector<float> time_ms, points2d, lines2d, points3d, lines3d, t_err_mm, r_err_deg;
  std::vector<float> features_ms, stereo_ms, hashing_ms, verify_ms;
};

PipelineConfig PipelineConfigFor(bool dark) {
  return dark ? PipelineConfig::DarkBackground() : PipelineConfig::LightBackground();
}

// Scenario of scene i of a row: 4 or 5 objects, camera 300..600 mm from the table centre
// (closer, a 40 cm spread no longer fits the 756 x 581 px view), objects over 40 cm.
// Another camera (`--camera`) narrows the spread in proportion to its field of view when that
// is narrower than the thesis camera's.
render::ScenarioParams ScenarioFor(const SceneRow& row, int i,
                                   const render::ScenarioParams& camera) {
  render::ScenarioParams p = camera;
  p.background = row.bg;
  p.occlusion = row.occ;
  p.n_objects = 4 + (i % 2);
  p.camera_distance_mm = 300.0f + 300.0f * static_cast<float>((i * 7) % 10) / 9.0f;
  p.spread_mm = 400.0f;
  if (p.custom_camera) {
    const double view = std::min(p.camera.width / p.camera.fx, p.camera.height / p.camera.fy);
    constexpr double kThesisView = 581.0 / 1136.4;  // narrower side over the focal length
    p.spread_mm = static_cast<float>(400.0 * std::min(1.0, view / kThesisView));
  }
  return p;
}

// For --verbose: every reported object that matches no truth object, with the nearest truth.
void PrintErrors(const std::vector<Model>& models, const std::vector<TruthObject>& truth,
                 const PipelineResult& result, uint64_t seed) {
  for (const RecognizedObject& o : result.objects) {
    const std::vector<RecognizedPose> one = {{o.model, o.cam_T_model}};
    if (MatchToTruth(models, truth, one).correct == 1) {
      std::printf("  seed %llu: ok %s (vote %.2f, verify %.2f %.2f)\n",
                  static_cast<unsigned long long>(seed), models[o.model].name, o.vote,
                  o.verify_score[0], o.verify_score[1]);
      continue;
    }
    int nearest = -1;
    float best = 1e9f;
    for (size_t i = 0; i < truth.size(); ++i) {
      const float d = (truth[i].cam_T_model.t_mm - o.cam_T_model.t_mm).norm();
      if (d < best) best = d, nearest = static_cast<int>(i);
    }
    const TruthObject& t = truth[nearest];
    std::printf(
        "  seed %llu: false %s (vote %.2f, verify %.2f %.2f); nearest truth %s at %.1f mm, "
        "%.1f deg\n",
        static_cast<unsigned long long>(seed), models[o.model].name, o.vote, o.verify_score[0],
        o.verify_score[1], models[t.model].name, best,
        t.model == o.model
            ? SymmetricRotationErrorDeg(models[o.model], o.cam_T_model.R, t.cam_T_model.R)
            : -1.0f);
  }
}

// Working volume over the rendered table (table frame, mm), as an integrator would set it.
const Eigen::Vector3f kTableVolumeMin(render::kTableVolumeMinMm);
const Eigen::Vector3f kTableVolumeMax(render::kTableVolumeMaxMm);

int RunBenchScenes(int argc, char** argv) {
  int per_row = 10;
  const char* json_path = nullptr;
  const char* models_dir = STEREOHASH_DEFAULT_MODELS_DIR;
  float budget_ms = 0;
  float min_fraction = -1;
  int fruitless = -1;
  bool verbose = false;
  // The working volume an integrator configures: the box over the table the objects can occupy
  // (table frame: z up from the table top, mm). Off: the stereo module's large default box.
  bool table_volume = true;
  MissCauses miss_causes;
  const char* only = nullptr;         // restrict to one background
  int seed_offset = 0;                // another set of scenes (the presets were chosen on offset 0)
  std::vector<const char*> settings;  // name=value overrides of the presets
  const char* preset = nullptr;       // detector preset (default: automatic)
  render::ScenarioParams camera;      // --camera: another camera than the thesis's
  bool monocular = false;             // the monocular mode on the left images instead
  float max_t_mm = 10.0f, max_r_deg = 10.0f;  // scoring (thesis: 10 mm, 10 deg)
  for (int i = 2; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    // Options with a numeric value all end by consuming it (++i): the same body on purpose.
    if (std::strcmp(argv[i], "--scenes-per-row") == 0 && has_value &&
        // NOLINTNEXTLINE(bugprone-branch-clone)
        ParseInt(argv[i + 1], 1, 1000, &per_row)) {
      ++i;
    } else if (std::strcmp(argv[i], "--json") == 0 && has_value) {
      json_path = argv[++i];
    } else if (std::strcmp(argv[i], "--models") == 0 && has_value) {
      models_dir = argv[++i];
    } else if (std::strcmp(argv[i], "--budget-ms") == 0 && has_value) {
      budget_ms = static_cast<float>(std::atof(argv[++i]));
    } else if (std::strcmp(argv[i], "--min-fraction") == 0 && has_value) {
      min_fraction = static_cast<float>(std::atof(argv[++i]));
    } else if (std::strcmp(argv[i], "--set") == 0 && has_value) {
      settings.push_back(argv[++i]);
    } else if (std::strcmp(argv[i], "--seed-offset") == 0 && has_value &&
               ParseInt(argv[i + 1], 0, 1000000000, &seed_offset)) {
      ++i;
    } else if (std::strcmp(argv[i], "--camera") == 0 && has_value &&
               render::NamedCamera(argv[i + 1], &camera)) {
      ++i;
    } else if (std::strcmp(argv[i], "--only") == 0 && has_value) {
      only = argv[++i];
    } else if (std::strcmp(argv[i], "--verbose") == 0) {
      verbose = true;
    } else if (std::strcmp(argv[i], "--monocular") == 0) {
      monocular = true;
    } else if (std::strcmp(argv[i], "--tolerance") == 0 && has_value &&
               std::sscanf(argv[i + 1], "%f,%f", &max_t_mm, &max_r_deg) == 2) {
      ++i;
    } else if (std::strcmp(argv[i], "--no-table-volume") == 0) {
      table_volume = false;
    } else if (std::strcmp(argv[i], "--fruitless") == 0 && has_value &&
               ParseInt(argv[i + 1], 1, 100000, &fruitless)) {
      ++i;
    } else if (std::strcmp(argv[i], "--features") == 0 && has_value &&
               (std::strcmp(argv[i + 1], "dark") == 0 || std::strcmp(argv[i + 1], "light") == 0 ||
                std::strcmp(argv[i + 1], "row") == 0)) {
      preset = argv[++i];
    } else {
      std::fprintf(
          stderr,
          "usage: stereohash bench scenes [--scenes-per-row N] [--json OUT] "
          "[--budget-ms MS] [--min-fraction F] [--fruitless N] [--features dark|light|row] "
          "[--set NAME=VALUE] [--only dark|light] [--seed-offset N] [--verbose] "
          "[--no-table-volume] [--camera thesis|wide|tele|hd] [--models DIR] [--monocular] "
          "[--tolerance MM,DEG]\n");
      return 2;
    }
  }
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());

  const Result<TableView> table = OpenDefaultTable();
  if (!table.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", table.status().message());
    return 1;
  }
  RenderModels models;
  Status st = LoadRenderModels(models_dir, *table, &models);
  if (!st.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", st.message());
    return 1;
  }
  auto pipeline = std::make_unique<Pipeline>();
  auto pair = std::make_unique<RenderedPair>();
  // The monocular mode: the left image, the rendered table's pose as the installation's.
  Result<AspectTableView> aspects = OpenDefaultAspectTable();
  if (monocular && !aspects.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", aspects.status().message());
    return 1;
  }
  std::unique_ptr<MonoPipeline> mono;
  ZeroedPtr<FeatureWorkspace> workspace;
  auto mono_result = std::make_unique<MonoResult>();
  MonoPipelineConfig mono_config = MonoPipelineConfig::Automatic();
  int mono_causes[3] = {};
  // The stereo pipeline's one-image rescue (PipelineConfig::rescue): set up for each scene.
  ZeroedPtr<MonoRecognizer> rescue;
  int rescue_added = 0, rescue_ran = 0;
  std::vector<float> rescue_ms;
  for (const char* setting : settings) {
    if (std::strncmp(setting, "mono.", 5) != 0) continue;
    if (const Status applied = ApplyMonoSetting(setting, &mono_config); !applied.ok()) {
      std::fprintf(stderr, "stereohash bench: %s\n", applied.message());
      return 2;
    }
  }
  if (monocular) {
    mono = std::make_unique<MonoPipeline>();
    workspace = MakeWorkspace<FeatureWorkspace>();  // any image size up to the maximum
  }
  SceneRow rows[] = {
      {"dark", "none", render::Background::kDark, render::Occlusion::kNone},
      {"dark", "some", render::Background::kDark, render::Occlusion::kSome},
      {"dark", "severe", render::Background::kDark, render::Occlusion::kSevere},
      {"light", "none", render::Background::kLight, render::Occlusion::kNone},
      {"light", "some", render::Background::kLight, render::Occlusion::kSome},
      {"light", "severe", render::Background::kLight, render::Occlusion::kSevere},
  };
  PipelineResult result;
  for (int r = 0; r < 6; ++r) {
    SceneRow& row = rows[r];
    if (only != nullptr && std::strcmp(only, row.background) != 0) continue;
    // The product's default (thresholds measured per image), or a preset when asked for:
    // `--features dark|light` for every row, `--features row` by the row's background.
    PipelineConfig config = PipelineConfig::Automatic();
    if (preset != nullptr && std::strcmp(preset, "row") == 0) {
      config = PipelineConfigFor(row.bg == render::Background::kDark);
    } else if (preset != nullptr) {
      config = PipelineConfigFor(preset[0] == 'd');
    }
    if (min_fraction >= 0) config.verify.min_fraction = min_fraction;
    if (fruitless > 0) config.recognizer.max_fruitless_bases = static_cast<uint32_t>(fruitless);
    for (const char* setting : settings) {
      if (std::strncmp(setting, "mono.", 5) == 0) continue;  // the monocular mode's
      if (const Status applied = ApplyPipelineSetting(setting, &config); !applied.ok()) {
        std::fprintf(stderr, "stereohash bench: %s\n", applied.message());
        return 2;
      }
    }
    for (int i = 0, attempt = 0; i < per_row && attempt < 4 * per_row; ++attempt) {
      // Seeds whose objects cannot be placed for the scenario are skipped (reported).
      const uint64_t seed = uint64_t(seed_offset) + uint64_t{1000} * (r + 1) + attempt;
      st = RenderPair(seed, ScenarioFor(row, i, camera), models, pair.get());
      if (!st.ok()) {
        std::fprintf(stderr, "scene %s/%s seed %llu skipped: %s\n", row.background, row.occlusion,
                     static_cast<unsigned long long>(seed), st.message());
        continue;
      }
      ++i;
      // Every scene brings its own calibration (camera distance varies) and its own table pose.
      PipelineConfig scene_config = config;
      if (table_volume) {
        scene_config.stereo.volume = WorkingVolume::InFrame(pair->generated.scene.left_T_table,
                                                            kTableVolumeMin, kTableVolumeMax);
        scene_config.table.known = true;
        scene_config.table.left_T_table = pair->generated.scene.left_T_table;
      }
      if (monocular) {
        const RigidTransform& left_T_table = pair->generated.scene.left_T_table;
        st = mono->Init(pair->generated.calib, 0, *aspects, table_volume ? &left_T_table : nullptr,
                        mono_config, NowNs);
        if (st.ok())
          st = mono->Process(pair->left_view(), budget_ms, *workspace, mono_result.get());
        if (st.ok()) {
          // The monocular result in the stereo result's place, for the scoring below.
          result = PipelineResult{};
          for (const RecognizedObject& o : mono_result->objects) (void)result.objects.push_back(o);
          result.points2d[0] = result.points2d[1] = mono_result->points2d;
          result.lines2d[0] = result.lines2d[1] = mono_result->lines2d;
          result.time.features_ms = mono_result->time.features_ms;
          result.time.hashing_ms = mono_result->time.recognition_ms;
          result.time.total_ms = mono_result->time.total_ms;
        }
      } else {
        st = pipeline->Init(pair->generated.calib, *table, scene_config, NowNs);
        // The one-image rescue: the left camera of this scene, its table when the scene's is
        // given.
        if (st.ok() && scene_config.rescue.enabled) {
          const RigidTransform& left_T_table = pair->generated.scene.left_T_table;
          st = aspects.ok() ? LendRescueRecognizer(*aspects, pair->generated.calib,
                                                   table_volume ? &left_T_table : nullptr,
                                                   mono_config.mono, pipeline.get(), &rescue)
                            : aspects.status();
        }
        if (st.ok())
          st = pipeline->Process(pair->left_view(), pair->right_view(), budget_ms, &result);
        if (st.ok()) {
          rescue_added += static_cast<int>(result.rescue.added);
          rescue_ran += result.rescue.ran ? 1 : 0;
          rescue_ms.push_back(result.time.rescue_ms);
        }
      }
      if (!st.ok()) {
        std::fprintf(stderr, "scene %s/%s seed %llu: %s\n", row.background, row.occlusion,
                     static_cast<unsigned long long>(seed), st.message());
        ++row.failed;
        continue;
      }
      const MatchCounts m =
          MatchToTruth(models.table, pair->truth, PosesOf(result), max_t_mm, max_r_deg);
      if (verbose) PrintErrors(models.table, pair->truth, result, seed);
      char label[32];
      std::snprintf(label, sizeof(label), "seed %llu", static_cast<unsigned long long>(seed));
      if (monocular) {
        ExplainMonoMisses(models.table, pair->truth, mono_result->objects, mono->features(),
                          mono->recognizer(), label, verbose, mono_causes, max_t_mm, max_r_deg);
      } else {
        ExplainMisses(models.table, pair->truth, result, *pipeline, label, verbose, &miss_causes,
                      max_t_mm, max_r_deg);
      }
      ++row.scenes;
      row.objects += static_cast<int>(pair->truth.size());
      row.correct += m.correct;
      row.missed += m.missed;
      row.false_alarms += m.false_alarms;
      row.t_err_mm.insert(row.t_err_mm.end(), m.translation_errors_mm.begin(),
                          m.translation_errors_mm.end());
      row.r_err_deg.insert(row.r_err_deg.end(), m.rotation_errors_deg.begin(),
                           m.rotation_errors_deg.end());
      row.time_ms.push_back(result.time.total_ms);
      row.features_ms.push_back(result.time.features_ms);
      row.stereo_ms.push_back(result.time.stereo_ms);
      row.hashing_ms.push_back(result.time.hashing_ms);
      row.verify_ms.push_back(result.time.verify_ms);
      row.scene_bases_tried += result.recognition.scene_bases_tried;
      row.points2d.push_back(float(result.points2d[0] + result.points2d[1]) * 0.5f);
      row.lines2d.push_back(float(result.lines2d[0] + result.lines2d[1]) * 0.5f);
      row.points3d.push_back(float(result.points3d));
      row.lines3d.push_back(float(result.lines3d));
    }
  }

  std::printf(
      "\nRendered scenes, %s%d thread%s); 2-D counts are per image (mean\n"
      "of left and right), all counts medians; correct = same model, centre within %.0f mm,\n"
      "rotation within %.0f deg (symmetry-aware); pose errors are medians over correct "
      "objects.\n\n",
      monocular ? "monocular mode on the left images (stage 'hashing' = recognition; "
                : "whole pipeline (hash fn 5, ",
      monocular ? 1 : pipeline->threads(), !monocular && pipeline->threads() != 1 ? "s" : "",
      double(max_t_mm), double(max_r_deg));
  std::printf("%-6s %-7s %6s %7s %7s %6s %6s %8s %8s %6s %6s %6s %6s %7s %7s\n", "backgr", "occlus",
              "scenes", "objects", "correct", "missed", "false", "med ms", "worst ms", "2D pts",
              "2D lin", "3D pts", "3D lin", "t mm", "R deg");
  std::string json = "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n  \"rows\": [";
  SceneRow total{"all", "all", render::Background::kDark, render::Occlusion::kNone};
  for (int r = 0; r < 7; ++r) {
    SceneRow& row = r < 6 ? rows[r] : total;
    if (r < 6) {
      total.scenes += row.scenes;
      total.objects += row.objects;
      total.correct += row.correct;
      total.missed += row.missed;
      total.false_alarms += row.false_alarms;
      total.failed += row.failed;
      total.scene_bases_tried += row.scene_bases_tried;
      for (auto [dst, src] : {std::pair{&total.time_ms, &row.time_ms},
                              {&total.points2d, &row.points2d},
                              {&total.lines2d, &row.lines2d},
                              {&total.points3d, &row.points3d},
                              {&total.lines3d, &row.lines3d},
                              {&total.t_err_mm, &row.t_err_mm},
                              {&total.r_err_deg, &row.r_err_deg},
                              {&total.features_ms, &row.features_ms},
                              {&total.stereo_ms, &row.stereo_ms},
                              {&total.hashing_ms, &row.hashing_ms},
                              {&total.verify_ms, &row.verify_ms}}) {
        dst->insert(dst->end(), src->begin(), src->end());
      }
    }
    std::printf("%-6s %-7s %6d %7d %7d %6d %6d %8.1f %8.1f %6.0f %6.0f %6.0f %6.0f %7.2f %7.2f\n",
                row.background, row.occlusion, row.scenes, row.objects, row.correct, row.missed,
                row.false_alarms, Median(row.time_ms), Max(row.time_ms), Median(row.points2d),
                Median(row.lines2d), Median(row.points3d), Median(row.lines3d),
                Median(row.t_err_mm), Median(row.r_err_deg));
    char buffer[1024];
    std::snprintf(
        buffer, sizeof(buffer),
        "%s\n    {\"background\": \"%s\", \"occlusion\": \"%s\", \"scenes\": %d, \"objects\": %d, "
        "\"correct\": %d, \"missed\": %d, \"false_alarms\": %d, \"failed\": %d, "
        "\"median_ms\": %.2f, \"worst_ms\": %.2f, \"median_stage_ms\": {\"features\": %.2f, "
        "\"stereo\": %.2f, \"hashing\": %.2f, \"verify\": %.2f}, \"points2d\": %.0f, "
        "\"lines2d\": %.0f, \"points3d\": %.0f, \"lines3d\": %.0f, \"median_t_err_mm\": %.3f, "
        "\"median_r_err_deg\": %.3f}",
        r ? "," : "", row.background, row.occlusion, row.scenes, row.objects, row.correct,
        row.missed, row.false_alarms, row.failed, Median(row.time_ms), Max(row.time_ms),
        Median(row.features_ms), Median(row.stereo_ms), Median(row.hashing_ms),
        Median(row.verify_ms), Median(row.points2d), Median(row.lines2d), Median(row.points3d),
        Median(row.lines3d), Median(row.t_err_mm), Median(row.r_err_deg));
    json += buffer;
  }
  json += "\n  ]\n}\n";
  const int found = total.correct + total.false_alarms;
  std::printf(
      "\ncorrect %.1f %% of objects, false alarms %.1f %% of reported objects; median stage "
      "times: features %.1f, stereo %.1f, hashing %.1f, verify %.1f ms; %d scenes failed\n",
      total.objects ? 100.0 * total.correct / total.objects : 0.0,
      found ? 100.0 * total.false_alarms / found : 0.0, Median(total.features_ms),
      Median(total.stereo_ms), Median(total.hashing_ms), Median(total.verify_ms), total.failed);
  if (monocular) {
    std::printf(
        "missed %d: at the true pose %d show under half of their corners and edges in the "
        "image's features, %d fail the image verification, %d were not found by the search\n",
        total.missed, mono_causes[0], mono_causes[1], mono_causes[2]);
  } else {
    std::printf(
        "missed %d: at the true pose %d fail the image verification (edges too weak or hidden), "
        "%d have under 30 %% 3-D support (stereo lost them), %d were not reached by the search\n",
        total.missed, miss_causes.no_edges, miss_causes.no_3d, miss_causes.not_searched);
    std::printf("scene bases tried %ld over %d scenes\n", total.scene_bases_tried, total.scenes);
    if (!rescue_ms.empty()) {
      std::printf(
          "rescue (one image, confirmed in both): ran in %d of %d scenes, added %d "
          "objects; %.1f ms median, %.1f ms worst\n",
          rescue_ran, total.scenes, rescue_added, Median(rescue_ms), Max(rescue_ms));
    }
  }
  if (json_path != nullptr && !WriteTextFile(json_path, json)) {
    std::fprintf(stderr, "stereohash bench: cannot write %s\n", json_path);
    return 1;
  }
  return total.failed == 0 ? 0 : 1;
}

// ---------------------------------------------------------------------------------------------
// bench synthetic

struct AlignedBlob {
  std::vector<uint8_t> storage;
  TableView view;
};

Status BuildTable(const std::vector<Model>& models, int hf, AlignedBlob* out) {
  TableBuildOptions options;
  options.hash_function = static_cast<HashFunction>(hf);
  auto blob = BuildTableBlob(models, options);
  if (!blob.ok()) return blob.status();
  out->storage.assign(blob->size() + 64, 0);
  uint8_t* p = out->storage.data();
  p += (64 - reinterpret_cast<uintptr_t>(p) % 64) % 64;  // table views need 8-byte alignment
  std::copy(blob->begin(), blob->end(), p);
  auto view = TableView::Open(p, blob->size());
  if (!view.ok()) return view.status();
  out->view = *view;
  return Status::Ok();
}

int RunBenchSynthetic(int argc, char** argv) {
  int n_scenes = 200;
  int features = 1000;
  const char* json_path = nullptr;
  const char* models_dir = STEREOHASH_DEFAULT_MODELS_DIR;
  for (int i = 2; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    // Options with a numeric value all end by consuming it (++i): the same body on purpose.
    if (std::strcmp(argv[i], "--scenes") == 0 && has_value &&
        // NOLINTNEXTLINE(bugprone-branch-clone)
        ParseInt(argv[i + 1], 1, 100000, &n_scenes)) {
      ++i;
    } else if (std::strcmp(argv[i], "--features") == 0 && has_value &&
               ParseInt(argv[i + 1], 10, 4000, &features)) {
      ++i;
    } else if (std::strcmp(argv[i], "--json") == 0 && has_value) {
      json_path = argv[++i];
    } else if (std::strcmp(argv[i], "--models") == 0 && has_value) {
      models_dir = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: stereohash bench synthetic [--scenes N] [--features N] [--json OUT] "
                   "[--models DIR]\n");
      return 2;
    }
  }
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());
  std::vector<Model> obj_models;
  Status st = LoadModelFolder(models_dir, &obj_models);
  if (!st.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", st.message());
    return 1;
  }
  auto scene = std::make_unique<SyntheticScene>();
  auto recognizer = std::make_unique<Recognizer>();
  static Vector<RecognizedObject, kMaxObjects> objects;
  constexpr float kVerifierMinFraction = 0.5f;  // SceneSupportVerifier's default
  SceneSupportVerifier verifier(kVerifierMinFraction);
  std::string json =
      "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n  \"hash_functions\": [";
  std::printf(
      "\nSynthetic 3-D scenes (1-5 objects, %d features, 20-40 %% of object features missing,\n"
      "noise 0.5-1 mm), recogniser with SceneSupportVerifier, %d scenes per hash function:\n\n",
      features, n_scenes);
  std::printf("%-3s %7s %7s %6s %6s %8s %8s %8s %8s\n", "hf", "objects", "correct", "missed",
              "false", "t mm", "R deg", "med ms", "worst ms");
  AlignedBlob hf5;
  // The same scenes at their true poses (independent of the hash function): objects whose
  // support there is below the verifier's threshold cannot be accepted by any search, and
  // refinement from the true pose gives the pose-error floor the feature noise sets.
  int truth_support_low = 0;
  std::vector<float> truth_t_err, truth_r_err;
  for (int hf = 1; hf <= 5; ++hf) {
    AlignedBlob table;
    st = BuildTable(obj_models, hf, &table);
    if (st.ok()) st = recognizer->Init(table.view, RecognizerConfig{});
    if (!st.ok()) {
      std::fprintf(stderr, "stereohash bench: hash fn %d: %s\n", hf, st.message());
      return 1;
    }
    std::vector<Model> models;
    for (uint32_t m = 0; m < table.view.model_count(); ++m) models.push_back(table.view.model(m));
    SyntheticSceneParams params;
    params.total_features = features;
    int objects_total = 0, correct = 0, missed = 0, false_alarms = 0;
    std::vector<float> t_err, r_err, time_ms;
    for (int s = 0; s < n_scenes; ++s) {
      GenerateSyntheticScene(models, params, 5000 + s, scene.get());
      const int64_t t0 = NowNs();
      st = recognizer->Recognize(scene->scene, verifier, Budget{}, objects);
      time_ms.push_back(float(NowNs() - t0) * 1e-6f);
      if (!st.ok()) {
        std::fprintf(stderr, "stereohash bench: %s\n", st.message());
        return 1;
      }
      std::vector<RecognizedPose> poses;
      for (const RecognizedObject& o : objects) poses.push_back({o.model, o.cam_T_model});
      const MatchCounts m = MatchToTruth(models, scene->truth, poses);
      objects_total += static_cast<int>(scene->truth.size());
      correct += m.correct;
      missed += m.missed;
      false_alarms += m.false_alarms;
      t_err.insert(t_err.end(), m.translation_errors_mm.begin(), m.translation_errors_mm.end());
      r_err.insert(r_err.end(), m.rotation_errors_deg.begin(), m.rotation_errors_deg.end());
      if (hf == 5) {
        for (const TruthObject& t : scene->truth) {
          const TruthPoseFit fit =
              FitFromTruePose(models[t.model], t.cam_T_model, scene->scene, recognizer->config());
          truth_support_low += fit.support < kVerifierMinFraction;
          truth_t_err.push_back(fit.t_err_mm);
          truth_r_err.push_back(fit.r_err_deg);
        }
      }
    }
    std::printf("%-3d %7d %7d %6d %6d %8.3f %8.3f %8.2f %8.2f\n", hf, objects_total, correct,
                missed, false_alarms, Median(t_err), Median(r_err), Median(time_ms), Max(time_ms));
    char buffer[512];
    std::snprintf(buffer, sizeof(buffer),
                  "%s\n    {\"hash_function\": %d, \"scenes\": %d, \"objects\": %d, \"correct\": "
                  "%d, \"missed\": %d, \"false_alarms\": %d, \"median_t_err_mm\": %.3f, "
                  "\"median_r_err_deg\": %.3f, \"median_ms\": %.3f, \"worst_ms\": %.3f}",
                  hf > 1 ? "," : "", hf, n_scenes, objects_total, correct, missed, false_alarms,
                  Median(t_err), Median(r_err), Median(time_ms), Max(time_ms));
    json += buffer;
    if (hf == 5) hf5 = std::move(table);
  }
  const size_t truth_objects = truth_t_err.size();
  std::printf(
      "\nAt the true poses (hash fn 5 run): %d of %zu objects (%.1f %%) have less than %.0f %% "
      "support even there;\nrefinement started from the true pose: median %.3f mm, %.3f deg.\n",
      truth_support_low, truth_objects,
      truth_objects ? 100.0 * truth_support_low / double(truth_objects) : 0.0,
      100.0 * kVerifierMinFraction, Median(truth_t_err), Median(truth_r_err));
  char truth_buffer[256];
  std::snprintf(truth_buffer, sizeof(truth_buffer),
                "\n  ],\n  \"true_pose\": {\"objects\": %zu, \"below_verifier_threshold\": %d, "
                "\"median_t_err_mm\": %.3f, \"median_r_err_deg\": %.3f},",
                truth_objects, truth_support_low, Median(truth_t_err), Median(truth_r_err));
  json += truth_buffer;
  json += "\n  \"hf5_time_per_scene\": [";

  // Time per scene against scene size (hash fn 5; five objects, a fixed number of scenes).
  std::printf(
      "\nhash fn 5, five objects, time per scene against scene features (%d scenes "
      "each):\n\n%8s %8s %8s %8s\n",
      std::min(n_scenes, 50), "features", "med ms", "worst ms", "correct");
  st = recognizer->Init(hf5.view, RecognizerConfig{});
  if (!st.ok()) return 1;
  std::vector<Model> models;
  for (uint32_t m = 0; m < hf5.view.model_count(); ++m) models.push_back(hf5.view.model(m));
  bool first = true;
  for (int n : {100, 250, 500, 1000, 1500, 2000}) {
    SyntheticSceneParams params;
    params.min_objects = params.max_objects = 5;
    params.total_features = n;
    std::vector<float> time_ms;
    int objects_total = 0, correct = 0;
    for (int s = 0; s < std::min(n_scenes, 50); ++s) {
      GenerateSyntheticScene(models, params, 9000 + s, scene.get());
      const int64_t t0 = NowNs();
      (void)recognizer->Recognize(scene->scene, verifier, Budget{}, objects);
      time_ms.push_back(float(NowNs() - t0) * 1e-6f);
      std::vector<RecognizedPose> poses;
      for (const RecognizedObject& o : objects) poses.push_back({o.model, o.cam_T_model});
      correct += MatchToTruth(models, scene->truth, poses).correct;
      objects_total += static_cast<int>(scene->truth.size());
    }
    std::printf("%8d %8.2f %8.2f %7.1f%%\n", n, Median(time_ms), Max(time_ms),
                objects_total ? 100.0 * correct / objects_total : 0.0);
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer),
                  "%s\n    {\"features\": %d, \"median_ms\": %.3f, \"worst_ms\": %.3f, "
                  "\"correct\": %d, \"objects\": %d}",
                  first ? "" : ",", n, Median(time_ms), Max(time_ms), correct, objects_total);
    json += buffer;
    first = false;
  }
  json += "\n  ]\n}\n";
  if (json_path != nullptr && !WriteTextFile(json_path, json)) {
    std::fprintf(stderr, "stereohash bench: cannot write %s\n", json_path);
    return 1;
  }
  return 0;
}

int RunBench(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "scenes") == 0) return RunBenchScenes(argc, argv);
  if (argc >= 2 && std::strcmp(argv[1], "synthetic") == 0) return RunBenchSynthetic(argc, argv);
  if (argc >= 2 && std::strcmp(argv[1], "recorded") == 0) return RunBenchRecorded(argc, argv);
  if (argc >= 2 && std::strcmp(argv[1], "textured") == 0) {
    // The OpenCV peer is in stereohash-cv (tools/cv_program.hpp); without it, or with --no-peer,
    // the texture path runs here alone.
    bool no_peer = false;
    for (int i = 2; i < argc; ++i) no_peer = no_peer || std::strcmp(argv[i], "--no-peer") == 0;
    if (!no_peer && CvProgramPresent()) return RunInCvProgram(argc, argv);
    return RunBenchTextured(argc, argv);
  }
  std::fprintf(
      stderr,
      "usage: stereohash bench scenes [--scenes-per-row N] [--json OUT] [--budget-ms MS]\n"
      "                               [--set NAME=VALUE] [--only dark|light] [--seed-offset N]\n"
      "                               [--features dark|light|row] [--verbose]\n"
      "       stereohash bench synthetic [--scenes N] [--features N] [--json OUT]\n"
      "       stereohash bench recorded DIR [--json OUT] [--verbose] [--no-table] [options]\n"
      "       stereohash bench textured (--recorded DIR | --rendered N) [--no-peer] [--json OUT]\n"
      "scenes:    rendered stereo pairs (dark/light x no/some/severe occlusion) through the whole\n"
      "           pipeline, reported like the thesis's table 5.5.\n"
      "synthetic: the recogniser alone on synthetic 3-D scenes, all five hash functions, and the\n"
      "           time per scene for 100..2000 features.\n"
      "recorded:  recorded stereo scenes with ground truth (DIR/sceneNN/...) through the\n"
      "           pipeline as `stereohash recognize` runs it.\n"
      "textured:  printed cartons (recorded or rendered) through the texture path and an OpenCV\n"
      "           peer.\n");
  return 2;
}

}  // namespace

SH_REGISTER_COMMAND(bench, "evaluation: rendered, recorded or synthetic 3-D scenes", RunBench);

}  // namespace sh::tools
