// `stereohash bench scenes|synthetic`: the thesis's evaluation grids, measured on this machine.
//
// scenes:    rendered stereo pairs through the recognition facade (the stereo pipeline, or the
//            monocular mode), one row per background x occlusion (thesis table 5.4), reported
//            like table 5.5.
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
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/verify.hpp"
#include "tables/aspect_file.hpp"
#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tools/bench_recognizer.hpp"
#include "tools/bench_recorded.hpp"
#include "tools/bench_scoring.hpp"
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
#include "tools/tablegen/table_builder.hpp"

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
      : bg(bg_), occ(occ_) {
    score.background = b;
    score.occlusion = o;
  }
  render::Background bg;
  render::Occlusion occ;
  ScoreRow score;
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
                 const Vector<RecognizedObject>& objects, uint64_t seed) {
  for (const RecognizedObject& o : objects) {
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

struct ScenesOptions {
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
  const char* only = nullptr;         // restrict to one background
  int seed_offset = 0;                // another set of scenes (the presets were chosen on offset 0)
  std::vector<const char*> settings;  // name=value overrides of the presets
  const char* preset = nullptr;       // detector preset (default: automatic)
  render::ScenarioParams camera;      // --camera: another camera than the thesis's
  bool monocular = false;             // the monocular mode on the left images instead
  float max_t_mm = 10.0f, max_r_deg = 10.0f;  // scoring (thesis: 10 mm, 10 deg)
};

// A flag, or an option whose value is valid, at argv[*i] (moved past the value); false: neither.
bool TakeScenesOption(int argc, char** argv, int* i, ScenesOptions* o) {
  const char* arg = argv[*i];
  const char* value = *i + 1 < argc ? argv[*i + 1] : nullptr;
  const auto is = [arg](const char* name) { return std::strcmp(arg, name) == 0; };
  bool taken = true;  // a value, when there is one, is consumed below
  if (is("--verbose")) {
    o->verbose = true;
    return true;
  }
  if (is("--monocular")) {
    o->monocular = true;
    return true;
  }
  if (is("--no-table-volume")) {
    o->table_volume = false;
    return true;
  }
  if (value == nullptr) return false;
  if (is("--scenes-per-row")) {
    taken = ParseInt(value, 1, 1000, &o->per_row);
  } else if (is("--json")) {
    o->json_path = value;
  } else if (is("--models")) {
    o->models_dir = value;
  } else if (is("--budget-ms")) {
    o->budget_ms = static_cast<float>(std::atof(value));
  } else if (is("--min-fraction")) {
    o->min_fraction = static_cast<float>(std::atof(value));
  } else if (is("--set")) {
    o->settings.push_back(value);
  } else if (is("--seed-offset")) {
    taken = ParseInt(value, 0, 1000000000, &o->seed_offset);
  } else if (is("--camera")) {
    taken = render::NamedCamera(value, &o->camera);
  } else if (is("--only")) {
    o->only = value;
  } else if (is("--tolerance")) {
    taken = std::sscanf(value, "%f,%f", &o->max_t_mm, &o->max_r_deg) == 2;
  } else if (is("--fruitless")) {
    taken = ParseInt(value, 1, 100000, &o->fruitless);
  } else if (is("--features")) {
    taken = std::strcmp(value, "dark") == 0 || std::strcmp(value, "light") == 0 ||
            std::strcmp(value, "row") == 0;
    if (taken) o->preset = value;
  } else {
    taken = false;
  }
  if (taken) ++*i;
  return taken;
}

bool ParseScenesOptions(int argc, char** argv, ScenesOptions* o) {
  for (int i = 2; i < argc; ++i) {
    if (TakeScenesOption(argc, argv, &i, o)) continue;
    std::fprintf(stderr,
                 "usage: stereohash bench scenes [--scenes-per-row N] [--json OUT] "
                 "[--budget-ms MS] [--min-fraction F] [--fruitless N] [--features dark|light|row] "
                 "[--set NAME=VALUE] [--only dark|light] [--seed-offset N] [--verbose] "
                 "[--no-table-volume] [--camera thesis|wide|tele|hd] [--models DIR] [--monocular] "
                 "[--tolerance MM,DEG]\n");
    return false;
  }
  return true;
}
// The stereo pipeline's settings of a row: the product's default (thresholds measured per
// image), or a preset when asked for (`--features dark|light` for every row, `--features row`
// by the row's background), with the command's settings on it; false when one is not known
// (said).
bool RowConfig(const ScenesOptions& o, const SceneRow& row, PipelineConfig* config) {
  *config = PipelineConfig::Automatic();
  if (o.preset != nullptr && std::strcmp(o.preset, "row") == 0) {
    *config = PipelineConfigFor(row.bg == render::Background::kDark);
  } else if (o.preset != nullptr) {
    *config = PipelineConfigFor(o.preset[0] == 'd');
  }
  if (o.min_fraction >= 0) config->verify.min_fraction = o.min_fraction;
  if (o.fruitless > 0) config->recognizer.max_fruitless_bases = static_cast<uint32_t>(o.fruitless);
  for (const char* setting : o.settings) {
    if (std::strncmp(setting, "mono.", 5) == 0) continue;  // the monocular mode's
    if (const Status applied = ApplyPipelineSetting(setting, config); !applied.ok()) {
      std::fprintf(stderr, "stereohash bench: %s\n", applied.message());
      return false;
    }
  }
  return true;
}

// What the rows share: the models, the facade and the figures beyond the rows.
struct ScenesBench {
  ScenesOptions o;
  TableView table;
  RenderModels models;
  PipelineConfig row_config;  // the row's settings, the facade's in place of its preset
  MonoPipelineConfig mono_config = MonoPipelineConfig::Automatic();
  // The rendered table of the scene, which the facade reads at each Init (every scene brings its
  // own calibration, the camera distance varies, and its own table pose).
  RigidTransform left_T_table;
  BenchRecognizer facade;
  std::unique_ptr<RenderedPair> pair = std::make_unique<RenderedPair>();
  MissTally misses;
  RescueTally rescue;  // the one-image rescue over the stereo frames
  ObjectRecognizer& recognizer() const { return *facade.recognizer; }
};

// The model set and, for the monocular mode, the aspect table; false when one failed (said).
bool LoadScenesModels(ScenesBench* b) {
  const Result<TableView> table = OpenDefaultTable();
  Status st = table.status();
  if (st.ok()) b->table = *table;
  if (st.ok()) st = LoadRenderModels(b->o.models_dir, b->table, &b->models);
  // The monocular mode: the left image, the rendered table's pose as the installation's.
  if (st.ok() && b->o.monocular) st = OpenDefaultAspectTable().status();
  if (!st.ok()) std::fprintf(stderr, "stereohash bench: %s\n", st.message());
  return st.ok();
}

// The monocular settings, and the first row's to check the others; false when one is not known
// (said).
bool TuneScenes(ScenesBench* b) {
  for (const char* setting : b->o.settings) {
    if (std::strncmp(setting, "mono.", 5) != 0) continue;
    if (const Status applied = ApplyMonoSetting(setting, &b->mono_config); !applied.ok()) {
      std::fprintf(stderr, "stereohash bench: %s\n", applied.message());
      return false;
    }
  }
  const SceneRow first{"dark", "none", render::Background::kDark, render::Occlusion::kNone};
  return RowConfig(b->o, first, &b->row_config);
}

// The facade on the row's settings (what it sets on top of them is the same for every row).
Status MakeScenesFacade(ScenesBench* b) {
  ObjectRecognizerConfig config = TunedRecognizerConfig(b->row_config, b->mono_config, NowNs);
  // With the table volume, the working volume over the rendered table and the table pose known,
  // as an integrator would set them; the monocular mode and the rescue lay objects onto it.
  config.table_known = config.volume_set = config.volume_in_table_frame = b->o.table_volume;
  config.mono_table_known = b->o.table_volume;
  std::copy(render::kTableVolumeMinMm, render::kTableVolumeMinMm + 3, config.volume_min_mm);
  std::copy(render::kTableVolumeMaxMm, render::kTableVolumeMaxMm + 3, config.volume_max_mm);
  config.left_T_table_at_init = &b->left_T_table;
  return MakeBenchRecognizer(config, &b->facade);
}

// The rendered pair through the facade, set up for its calibration and table: the stereo pair,
// or the left image in the monocular mode.
Status RecognizeRendered(ScenesBench* b) {
  const RenderedPair& pair = *b->pair;
  b->left_T_table = pair.generated.scene.left_T_table;
  ObjectRecognizer& recognizer = b->recognizer();
  SH_RETURN_IF_ERROR(recognizer.Init(pair.generated.calib, ModelSet(&b->table, nullptr), ~0u));
  RecognitionOutput* out = b->facade.output.get();
  if (b->o.monocular) return recognizer.ProcessMonocular(0, pair.left_view(), b->o.budget_ms, out);
  const StereoInput input{FrameView::Gray(pair.left_view()), FrameView::Gray(pair.right_view()),
                          pair.left_view(), pair.right_view()};
  SH_RETURN_IF_ERROR(recognizer.Process(input, b->o.budget_ms, out));
  b->rescue.Add(recognizer.stereo_result());
  return Status::Ok();
}

// Scores the recognised pair into its row, with why its objects were missed.
void ScoreRendered(ScenesBench* b, uint64_t seed, ScoreRow* row) {
  const ObjectRecognizer& recognizer = b->recognizer();
  const std::vector<Model>& models = b->models.table;
  const std::vector<TruthObject>& truth = b->pair->truth;
  const bool mono = b->o.monocular;
  const Vector<RecognizedObject>& objects =
      mono ? static_cast<const Vector<RecognizedObject>&>(recognizer.mono_result()->objects)
           : static_cast<const Vector<RecognizedObject>&>(recognizer.stereo_result().objects);
  std::vector<RecognizedPose> poses;
  for (const RecognizedObject& o : objects) poses.push_back({o.model, o.cam_T_model});
  const MatchCounts m = MatchToTruth(models, truth, poses, b->o.max_t_mm, b->o.max_r_deg);
  if (b->o.verbose) PrintErrors(models, truth, objects, seed);
  char label[32];
  std::snprintf(label, sizeof(label), "seed %llu", static_cast<unsigned long long>(seed));
  if (mono) {
    MonoPipeline& pipeline = *recognizer.mono_pipeline();
    ExplainMonoMisses(models, truth, recognizer.mono_result()->objects, pipeline.features(),
                      pipeline.recognizer(), label, b->o.verbose, b->misses.mono, b->o.max_t_mm,
                      b->o.max_r_deg);
    row->AddMonoFrame(*recognizer.mono_result());
  } else {
    ExplainMisses(models, truth, recognizer.stereo_result(), recognizer.pipeline(), label,
                  b->o.verbose, &b->misses.stereo, b->o.max_t_mm, b->o.max_r_deg);
    row->AddStereoFrame(recognizer.stereo_result());
  }
  row->AddMatch(m, truth.size());
}

// The row's scenes: rendered (seeds whose objects cannot be placed for the scenario are
// skipped, and said), recognised and scored; false when its settings are not known (said).
bool RunRow(ScenesBench* b, int r, SceneRow* row) {
  if (!RowConfig(b->o, *row, &b->row_config)) return false;
  const int per_row = b->o.per_row;
  for (int i = 0, attempt = 0; i < per_row && attempt < 4 * per_row; ++attempt) {
    const uint64_t seed = uint64_t(b->o.seed_offset) + uint64_t{1000} * (r + 1) + attempt;
    const auto seed_ull = static_cast<unsigned long long>(seed);
    const char* background = row->score.background.c_str();
    const char* occlusion = row->score.occlusion.c_str();
    Status st = RenderPair(seed, ScenarioFor(*row, i, b->o.camera), b->models, b->pair.get());
    if (!st.ok()) {
      std::fprintf(stderr, "scene %s/%s seed %llu skipped: %s\n", background, occlusion, seed_ull,
                   st.message());
      continue;
    }
    ++i;
    st = RecognizeRendered(b);
    if (!st.ok()) {
      std::fprintf(stderr, "scene %s/%s seed %llu: %s\n", background, occlusion, seed_ull,
                   st.message());
      ++row->score.failed;
      continue;
    }
    ScoreRendered(b, seed, &row->score);
  }
  return true;
}

// The table's heading: what ran, the threads and the scoring.
void PrintScenesHeading(const ScenesBench& b) {
  const bool mono = b.o.monocular;
  const int threads = mono ? 1 : b.recognizer().pipeline().threads();
  std::printf(
      "\nRendered scenes, %s%d thread%s); 2-D counts are per image (mean\n"
      "of left and right), all counts medians; correct = same model, centre within %.0f mm,\n"
      "rotation within %.0f deg (symmetry-aware); pose errors are medians over correct "
      "objects.\n\n",
      mono ? "monocular mode on the left images (stage 'hashing' = recognition; "
           : "whole pipeline (hash fn 5, ",
      threads, !mono && threads != 1 ? "s" : "", double(b.o.max_t_mm), double(b.o.max_r_deg));
}

// Recall, false alarms, stage times, failures, the misses' causes and the rescue's figures.
void PrintScenesSummary(const ScenesBench& b, const ScoreRow& total) {
  std::printf(
      "\ncorrect %.1f %% of objects, false alarms %.1f %% of reported objects; median stage "
      "times: features %.1f, stereo %.1f, hashing %.1f, verify %.1f ms; %d scenes failed\n",
      Percent(total.correct, total.objects),
      Percent(total.false_alarms, total.correct + total.false_alarms), Median(total.features_ms),
      Median(total.stereo_ms), Median(total.hashing_ms), Median(total.verify_ms), total.failed);
  b.misses.Print(b.o.monocular, total);
  if (!b.o.monocular && !b.rescue.ms.empty()) b.rescue.Print(total.scenes);
}

int RunBenchScenes(int argc, char** argv) {
  auto bench = std::make_unique<ScenesBench>();
  if (!ParseScenesOptions(argc, argv, &bench->o)) return 2;
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());
  if (bench->o.monocular && !bench->o.table_volume) {
    // The facade's one camera lays objects onto a known table; it does not guess depths.
    std::fprintf(stderr,
                 "stereohash bench: %s: --monocular needs the rendered table (no "
                 "--no-table-volume)\n",
                 kMonoNeedsTablePlane);
    return 2;
  }
  if (!LoadScenesModels(bench.get())) return 1;
  if (!TuneScenes(bench.get())) return 2;
  if (const Status st = MakeScenesFacade(bench.get()); !st.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", st.message());
    return 1;
  }
  SceneRow rows[] = {
      {"dark", "none", render::Background::kDark, render::Occlusion::kNone},
      {"dark", "some", render::Background::kDark, render::Occlusion::kSome},
      {"dark", "severe", render::Background::kDark, render::Occlusion::kSevere},
      {"light", "none", render::Background::kLight, render::Occlusion::kNone},
      {"light", "some", render::Background::kLight, render::Occlusion::kSome},
      {"light", "severe", render::Background::kLight, render::Occlusion::kSevere},
  };
  for (int r = 0; r < 6; ++r) {
    const char* only = bench->o.only;
    if (only != nullptr && rows[r].score.background != only) continue;
    if (!RunRow(bench.get(), r, &rows[r])) return 2;
  }
  PrintScenesHeading(*bench);
  PrintScoreHeader();
  std::string json = "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n  \"rows\": [";
  ScoreRow total;
  total.background = total.occlusion = "all";
  for (int r = 0; r < 7; ++r) {
    if (r < 6) total.Add(rows[r].score);
    const ScoreRow& row = r < 6 ? rows[r].score : total;
    PrintScoreRow(row);
    json += (r ? ",\n    " : "\n    ") + ScoreRowJson(row, true);
  }
  json += "\n  ]\n}\n";
  PrintScenesSummary(*bench, total);
  if (bench->o.json_path != nullptr && !WriteTextFile(bench->o.json_path, json)) {
    std::fprintf(stderr, "stereohash bench: cannot write %s\n", bench->o.json_path);
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

struct SyntheticOptions {
  int n_scenes = 200;
  int features = 1000;
  const char* json_path = nullptr;
  const char* models_dir = STEREOHASH_DEFAULT_MODELS_DIR;
};

bool ParseSyntheticOptions(int argc, char** argv, SyntheticOptions* o) {
  for (int i = 2; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    // Options with a numeric value all end by consuming it (++i): the same body on purpose.
    if (std::strcmp(argv[i], "--scenes") == 0 && has_value &&
        // NOLINTNEXTLINE(bugprone-branch-clone)
        ParseInt(argv[i + 1], 1, 100000, &o->n_scenes)) {
      ++i;
    } else if (std::strcmp(argv[i], "--features") == 0 && has_value &&
               ParseInt(argv[i + 1], 10, 4000, &o->features)) {
      ++i;
    } else if (std::strcmp(argv[i], "--json") == 0 && has_value) {
      o->json_path = argv[++i];
    } else if (std::strcmp(argv[i], "--models") == 0 && has_value) {
      o->models_dir = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: stereohash bench synthetic [--scenes N] [--features N] [--json OUT] "
                   "[--models DIR]\n");
      return false;
    }
  }
  return true;
}

constexpr float kVerifierMinFraction = 0.5f;  // SceneSupportVerifier's default

// The recogniser, its verifier and the scenes, shared by every hash function.
struct SyntheticBench {
  SyntheticOptions o;
  std::vector<Model> obj_models;
  std::unique_ptr<SyntheticScene> scene = std::make_unique<SyntheticScene>();
  std::unique_ptr<Recognizer> recognizer = std::make_unique<Recognizer>();
  Vector<RecognizedObject, kMaxObjects> objects;
  SceneSupportVerifier verifier{kVerifierMinFraction};
  // The same scenes at their true poses (independent of the hash function): objects whose
  // support there is below the verifier's threshold cannot be accepted by any search, and
  // refinement from the true pose gives the pose-error floor the feature noise sets.
  int truth_support_low = 0;
  std::vector<float> truth_t_err, truth_r_err;
};

std::vector<Model> TableModels(const TableView& table) {
  std::vector<Model> models;
  for (uint32_t m = 0; m < table.model_count(); ++m) models.push_back(table.model(m));
  return models;
}

// The current scene's objects refined from their true poses (the hash fn 5 run).
void FitTruePoses(const std::vector<Model>& models, SyntheticBench* b) {
  for (const TruthObject& t : b->scene->truth) {
    const TruthPoseFit fit =
        FitFromTruePose(models[t.model], t.cam_T_model, b->scene->scene, b->recognizer->config());
    b->truth_support_low += fit.support < kVerifierMinFraction;
    b->truth_t_err.push_back(fit.t_err_mm);
    b->truth_r_err.push_back(fit.r_err_deg);
  }
}

// The scenes through the recogniser on hash function hf's table: one line and one JSON row.
Status RunHashFunction(int hf, const AlignedBlob& table, SyntheticBench* b, std::string* json) {
  SH_RETURN_IF_ERROR(b->recognizer->Init(table.view, RecognizerConfig{}));
  const std::vector<Model> models = TableModels(table.view);
  SyntheticSceneParams params;
  params.total_features = b->o.features;
  int objects_total = 0;
  MatchCounts sum;  // counts and errors over the scenes
  std::vector<float> time_ms;
  for (int s = 0; s < b->o.n_scenes; ++s) {
    GenerateSyntheticScene(models, params, 5000 + s, b->scene.get());
    const int64_t t0 = NowNs();
    const Status st = b->recognizer->Recognize(b->scene->scene, b->verifier, Budget{}, b->objects);
    time_ms.push_back(float(NowNs() - t0) * 1e-6f);
    if (!st.ok()) return st;
    std::vector<RecognizedPose> poses;
    for (const RecognizedObject& o : b->objects) poses.push_back({o.model, o.cam_T_model});
    const MatchCounts m = MatchToTruth(models, b->scene->truth, poses);
    objects_total += static_cast<int>(b->scene->truth.size());
    sum.correct += m.correct;
    sum.missed += m.missed;
    sum.false_alarms += m.false_alarms;
    std::vector<float>&t_err = sum.translation_errors_mm, &r_err = sum.rotation_errors_deg;
    t_err.insert(t_err.end(), m.translation_errors_mm.begin(), m.translation_errors_mm.end());
    r_err.insert(r_err.end(), m.rotation_errors_deg.begin(), m.rotation_errors_deg.end());
    if (hf == 5) FitTruePoses(models, b);
  }
  const float t_med = Median(sum.translation_errors_mm), r_med = Median(sum.rotation_errors_deg);
  std::printf("%-3d %7d %7d %6d %6d %8.3f %8.3f %8.2f %8.2f\n", hf, objects_total, sum.correct,
              sum.missed, sum.false_alarms, t_med, r_med, Median(time_ms), Max(time_ms));
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer),
                "%s\n    {\"hash_function\": %d, \"scenes\": %d, \"objects\": %d, \"correct\": "
                "%d, \"missed\": %d, \"false_alarms\": %d, \"median_t_err_mm\": %.3f, "
                "\"median_r_err_deg\": %.3f, \"median_ms\": %.3f, \"worst_ms\": %.3f}",
                hf > 1 ? "," : "", hf, b->o.n_scenes, objects_total, sum.correct, sum.missed,
                sum.false_alarms, t_med, r_med, Median(time_ms), Max(time_ms));
  *json += buffer;
  return Status::Ok();
}

// What the search cannot reach: support and refinement at the true poses (hash fn 5 run).
void ReportTruePoses(const SyntheticBench& b, std::string* json) {
  const size_t truth_objects = b.truth_t_err.size();
  std::printf(
      "\nAt the true poses (hash fn 5 run): %d of %zu objects (%.1f %%) have less than %.0f %% "
      "support even there;\nrefinement started from the true pose: median %.3f mm, %.3f deg.\n",
      b.truth_support_low, truth_objects,
      truth_objects ? 100.0 * b.truth_support_low / double(truth_objects) : 0.0,
      100.0 * kVerifierMinFraction, Median(b.truth_t_err), Median(b.truth_r_err));
  char truth_buffer[256];
  std::snprintf(truth_buffer, sizeof(truth_buffer),
                "\n  ],\n  \"true_pose\": {\"objects\": %zu, \"below_verifier_threshold\": %d, "
                "\"median_t_err_mm\": %.3f, \"median_r_err_deg\": %.3f},",
                truth_objects, b.truth_support_low, Median(b.truth_t_err), Median(b.truth_r_err));
  *json += truth_buffer;
}

// Time per scene against scene size (hash fn 5; five objects, a fixed number of scenes).
Status TimeAgainstFeatures(const AlignedBlob& hf5, SyntheticBench* b, std::string* json) {
  const int n_scenes = std::min(b->o.n_scenes, 50);
  std::printf(
      "\nhash fn 5, five objects, time per scene against scene features (%d scenes "
      "each):\n\n%8s %8s %8s %8s\n",
      n_scenes, "features", "med ms", "worst ms", "correct");
  SH_RETURN_IF_ERROR(b->recognizer->Init(hf5.view, RecognizerConfig{}));
  const std::vector<Model> models = TableModels(hf5.view);
  *json += "\n  \"hf5_time_per_scene\": [";
  bool first = true;
  for (int n : {100, 250, 500, 1000, 1500, 2000}) {
    SyntheticSceneParams params;
    params.min_objects = params.max_objects = 5;
    params.total_features = n;
    std::vector<float> time_ms;
    int objects_total = 0, correct = 0;
    for (int s = 0; s < n_scenes; ++s) {
      GenerateSyntheticScene(models, params, 9000 + s, b->scene.get());
      const int64_t t0 = NowNs();
      (void)b->recognizer->Recognize(b->scene->scene, b->verifier, Budget{}, b->objects);
      time_ms.push_back(float(NowNs() - t0) * 1e-6f);
      std::vector<RecognizedPose> poses;
      for (const RecognizedObject& o : b->objects) poses.push_back({o.model, o.cam_T_model});
      correct += MatchToTruth(models, b->scene->truth, poses).correct;
      objects_total += static_cast<int>(b->scene->truth.size());
    }
    std::printf("%8d %8.2f %8.2f %7.1f%%\n", n, Median(time_ms), Max(time_ms),
                Percent(correct, objects_total));
    char buffer[256];
    std::snprintf(buffer, sizeof(buffer),
                  "%s\n    {\"features\": %d, \"median_ms\": %.3f, \"worst_ms\": %.3f, "
                  "\"correct\": %d, \"objects\": %d}",
                  first ? "" : ",", n, Median(time_ms), Max(time_ms), correct, objects_total);
    *json += buffer;
    first = false;
  }
  return Status::Ok();
}

// Every hash function on the same scenes; the hash fn 5 table is kept in *hf5.
bool RunHashFunctions(SyntheticBench* b, AlignedBlob* hf5, std::string* json) {
  std::printf(
      "\nSynthetic 3-D scenes (1-5 objects, %d features, 20-40 %% of object features missing,\n"
      "noise 0.5-1 mm), recogniser with SceneSupportVerifier, %d scenes per hash function:\n\n",
      b->o.features, b->o.n_scenes);
  std::printf("%-3s %7s %7s %6s %6s %8s %8s %8s %8s\n", "hf", "objects", "correct", "missed",
              "false", "t mm", "R deg", "med ms", "worst ms");
  for (int hf = 1; hf <= 5; ++hf) {
    AlignedBlob table;
    Status st = BuildTable(b->obj_models, hf, &table);
    if (st.ok()) st = RunHashFunction(hf, table, b, json);
    if (!st.ok()) {
      std::fprintf(stderr, "stereohash bench: hash fn %d: %s\n", hf, st.message());
      return false;
    }
    if (hf == 5) *hf5 = std::move(table);
  }
  return true;
}

int RunBenchSynthetic(int argc, char** argv) {
  auto bench = std::make_unique<SyntheticBench>();
  if (!ParseSyntheticOptions(argc, argv, &bench->o)) return 2;
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());
  const Status st = LoadModelFolder(bench->o.models_dir, &bench->obj_models);
  if (!st.ok()) {
    std::fprintf(stderr, "stereohash bench: %s\n", st.message());
    return 1;
  }
  std::string json =
      "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n  \"hash_functions\": [";
  AlignedBlob hf5;
  if (!RunHashFunctions(bench.get(), &hf5, &json)) return 1;
  ReportTruePoses(*bench, &json);
  if (!TimeAgainstFeatures(hf5, bench.get(), &json).ok()) return 1;
  json += "\n  ]\n}\n";
  const char* json_path = bench->o.json_path;
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
