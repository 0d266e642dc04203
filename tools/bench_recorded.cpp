// `stereohash bench recorded DIR`: the pipeline, run exactly as `stereohash recognize` runs it,
// on every scene of a recorded set (DIR/calib.yaml, DIR/table.yaml, DIR/sceneNN/{left.png,
// right.png, truth.json}; format in docs/pipeline.md), scored against the truth: thesis table
// 5.5 per background x occlusion row, recall by visibility, false alarms, pose errors, frame
// times, and why each missed object was missed at its true pose.
#include "tools/bench_recorded.hpp"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "recog/base/printable.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tools/command.hpp"
#include "tools/eval/image_degrade.hpp"
#include "tools/eval/mini_json.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/miss_causes.hpp"
#include "tools/mono_misses.hpp"
#include "tools/mono_setup.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

// Scoring of the recorded sets (their README): same model, position within 5 mm and rotation
// within 5 degrees, modulo the model's symmetries (--tolerance changes it).
constexpr float kMaxPositionErrorMm = 5.0f;
constexpr float kMaxRotationErrorDeg = 5.0f;

// Visibility bins: under 40 %, 40-70 %, 70 % and more (of the silhouette, mean of both images).
constexpr int kVisibilityBins = 3;
const char* const kVisibilityNames[kVisibilityBins] = {"under 40 %", "40-70 %", "70 % and more"};
int VisibilityBin(float visible) { return visible < 0.4f ? 0 : visible < 0.7f ? 1 : 2; }

void PrintHelp() {
  std::printf(
      "usage: stereohash bench recorded DIR [--json OUT] [--verbose] [--no-table [--carry-table]]\n"
      "                                     [--monocular left|right | --compare]\n"
      "                                     [--set NAME=VALUE ...] [recognize options]\n"
      "Runs the pipeline as `stereohash recognize` does on every scene of a recorded set\n"
      "(DIR/calib.yaml, DIR/table.yaml if present, DIR/*/left.png, right.png, truth.json) and\n"
      "scores it: correct = same model, position within 5 mm, rotation within 5 deg\n"
      "(symmetry-aware).\n"
      "  --json      write the figures, with a summary {correct, missed, false_alarms, objects}\n"
      "  --verbose   one line per false alarm and per miss (with its cause at the true pose)\n"
      "  --no-table  ignore DIR/table.yaml (as a user without a table file)\n"
      "  --carry-table  the scenes in order as the frames of one fixed cell: the plane estimated\n"
      "              in the first frames is confirmed and carried to the next (firmware\n"
      "              table_estimate = carry); needs no table file (--no-table)\n"
      "  --set NAME=VALUE  override one pipeline setting (as `bench scenes --set`); mono.NAME\n"
      "              for the monocular recogniser; the pipeline's settings:\n%s\n"
      "              the monocular recogniser's:\n%s\n"
      "  --monocular left|right  the monocular mode on that camera's images instead\n"
      "  --compare   the stereo pipeline and the monocular mode (left images) side by side\n"
      "  --tolerance MM,DEG  scoring tolerances (default 5,5)\n"
      "  --cpu-time  time stages by this process's CPU time (a loaded machine stretches wall\n"
      "              time; threads add up)\n"
      "  --noise SIGMA[,SIGMA...]  sensor noise added to every image before recognition, grey\n"
      "              levels at mid grey (half read, half shot noise; seeded by the scene's name,\n"
      "              so reproducible); one run per level, then recall against noise\n"
      "  --blur SIGMA  Gaussian defocus in pixels, before the noise\n"
      "  --gain G    exposure factor (clipped at white), before the noise\n"
      "%s",
      PipelineSettingNames("                ", 94).c_str(),
      MonoSettingNames("                ", 94).c_str(), kRecognizeOptionsHelp);
}

// DIR/NAME/, the prefix of a scene's files.
std::string SceneFolderPath(const std::string& dir, const std::string& name) {
  std::string path = dir;
  path.append("/").append(name).append("/");
  return path;
}

bool IsFile(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Scene folders of DIR: sub-folders holding left.png, right.png and truth.json, sorted by name.
std::vector<std::string> SceneFolders(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return names;
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    const std::string base = SceneFolderPath(dir, name);
    if (IsFile(base + "left.png") && IsFile(base + "right.png") && IsFile(base + "truth.json")) {
      names.push_back(name);
    }
  }
  closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

struct SceneTruth {
  std::string background, occlusion;
  std::vector<TruthObject> objects;
  std::vector<float> visible;  // mean of the left and right fraction
};

Status ParseTruth(const std::string& path, const ModelSet& models, SceneTruth* out) {
  std::string text;
  if (!ReadTextFile(path, &text)) {
    return Status::Error(StatusCode::kNotFound, "cannot read %s", path.c_str());
  }
  Json json;
  if (!JsonReader(text).Parse(&json) || json.type != Json::kObject) {
    return Status::Error(StatusCode::kInvalidArgument, "%s is not a JSON object", path.c_str());
  }
  out->background = json["background"].text;
  out->occlusion = json["occlusion"].text;
  const Json& objects = json["objects"];
  if (objects.type != Json::kArray) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: no \"objects\" list", path.c_str());
  }
  for (const Json& o : objects.items) {
    const int model = models.Find(o["model"].text.c_str());
    if (model < 0) {
      return Status::Error(StatusCode::kInvalidArgument, "%s: model '%s' is not in the tables",
                           path.c_str(), o["model"].text.c_str());
    }
    const Json& R = o["R"];
    const Json& t = o["t"];
    if (R.size() != 3 || t.size() != 3) {
      return Status::Error(StatusCode::kInvalidArgument, "%s: object without a 3x3 R and a t",
                           path.c_str());
    }
    TruthObject truth;
    truth.model = model;
    for (int r = 0; r < 3; ++r) {
      if (R[r].size() != 3) {
        return Status::Error(StatusCode::kInvalidArgument, "%s: R is not 3x3", path.c_str());
      }
      for (int c = 0; c < 3; ++c) truth.cam_T_model.R(r, c) = static_cast<float>(R[r][c].number);
      truth.cam_T_model.t_mm(r) = static_cast<float>(t[r].number);
    }
    const Json& visible = o["visible"];
    const float v = visible.size() == 2
                        ? static_cast<float>(0.5 * (visible[0].number + visible[1].number))
                        : 1.0f;
    out->objects.push_back(truth);
    out->visible.push_back(v);
  }
  return Status::Ok();
}

struct Row {
  std::string background, occlusion;
  int scenes = 0, objects = 0, correct = 0, missed = 0, false_alarms = 0;
  long scene_bases_tried = 0;  // summed over the scenes: the search's cost, machine-independent
  std::vector<float> time_ms, points2d, lines2d, points3d, lines3d, t_err_mm, r_err_deg;
  // Errors of the same correct objects before the final fit to the image edges.
  std::vector<float> feature_t_err_mm, feature_r_err_deg;
  std::vector<float> features_ms, stereo_ms, hashing_ms, verify_ms;

  void Add(const Row& o) {
    scenes += o.scenes;
    objects += o.objects;
    correct += o.correct;
    missed += o.missed;
    false_alarms += o.false_alarms;
    scene_bases_tried += o.scene_bases_tried;
    for (auto [dst, src] : {std::pair{&time_ms, &o.time_ms},
                            {&points2d, &o.points2d},
                            {&lines2d, &o.lines2d},
                            {&points3d, &o.points3d},
                            {&lines3d, &o.lines3d},
                            {&t_err_mm, &o.t_err_mm},
                            {&r_err_deg, &o.r_err_deg},
                            {&feature_t_err_mm, &o.feature_t_err_mm},
                            {&feature_r_err_deg, &o.feature_r_err_deg},
                            {&features_ms, &o.features_ms},
                            {&stereo_ms, &o.stereo_ms},
                            {&hashing_ms, &o.hashing_ms},
                            {&verify_ms, &o.verify_ms}}) {
      dst->insert(dst->end(), src->begin(), src->end());
    }
  }
};

void PrintRow(const Row& row) {
  std::printf("%-6s %-7s %6d %7d %7d %6d %6d %8.1f %8.1f %6.0f %6.0f %6.0f %6.0f %7.2f %7.2f\n",
              row.background.c_str(), row.occlusion.c_str(), row.scenes, row.objects, row.correct,
              row.missed, row.false_alarms, Median(row.time_ms), Max(row.time_ms),
              Median(row.points2d), Median(row.lines2d), Median(row.points3d), Median(row.lines3d),
              Median(row.t_err_mm), Median(row.r_err_deg));
}

std::string RowJson(const Row& row) {
  char buffer[1024];
  std::snprintf(buffer, sizeof(buffer),
                "{\"background\": \"%s\", \"occlusion\": \"%s\", \"scenes\": %d, \"objects\": %d, "
                "\"correct\": %d, \"missed\": %d, \"false_alarms\": %d, \"median_ms\": %.2f, "
                "\"worst_ms\": %.2f, \"median_stage_ms\": {\"features\": %.2f, \"stereo\": %.2f, "
                "\"hashing\": %.2f, \"verify\": %.2f}, \"points2d\": %.0f, \"lines2d\": %.0f, "
                "\"points3d\": %.0f, \"lines3d\": %.0f, \"median_t_err_mm\": %.3f, "
                "\"median_r_err_deg\": %.3f}",
                row.background.c_str(), row.occlusion.c_str(), row.scenes, row.objects, row.correct,
                row.missed, row.false_alarms, Median(row.time_ms), Max(row.time_ms),
                Median(row.features_ms), Median(row.stereo_ms), Median(row.hashing_ms),
                Median(row.verify_ms), Median(row.points2d), Median(row.lines2d),
                Median(row.points3d), Median(row.lines3d), Median(row.t_err_mm),
                Median(row.r_err_deg));
  return buffer;
}

// --noise 0,3,6: the levels, each in 0..64 grey levels.
bool ParseNoiseLevels(const char* text, std::vector<float>* levels) {
  levels->clear();
  const char* p = text;
  for (;;) {
    char* end = nullptr;
    const float v = std::strtof(p, &end);
    if (end == p || !(v >= 0.0f && v <= 64.0f) || (*end != ',' && *end != '\0')) return false;
    levels->push_back(v);
    if (*end == '\0') return true;
    p = end + 1;  // past the comma: another level must follow
  }
}

// An image as loaded, degraded in place: grey files in their grey plane, colour files in their
// RGB channels (the grey plane is made again from them).
Status DegradeLoaded(const ImageDegradation& degradation, uint64_t seed, LoadedImage* image) {
  if (degradation.none()) return Status::Ok();
  const int w = image->view.width, h = image->view.height;
  if (image->frame.format == FrameFormat::kGray8) {
    return DegradeImage(degradation, seed, w, h, 1, image->grey.data());
  }
  SH_RETURN_IF_ERROR(DegradeImage(degradation, seed, w, h, 3, image->pixels.data()));
  return FrameToGray(image->frame, GrayView{image->grey.data(), w, h, w});
}

// The figures of one system (stereo or monocular) over every scene of the set.
struct Summary {
  Row total;
  MissCauses causes;
  int mono_causes[3] = {};  // monocular misses: no features, no edges, not found
  int vis_objects[kVisibilityBins] = {}, vis_correct[kVisibilityBins] = {};
  std::string rows_json, scene_json, vis_json;
  // Table estimates: made, accepted, their errors against DIR/table.yaml, their time.
  int estimates = 0, estimates_accepted = 0;
  // Frames that took the carried plane, and planes dropped (--carry-table).
  int carried = 0, drops = 0;
  std::vector<float> normal_err_deg, offset_err_mm, table_ms;
  // The one-image rescue: frames it ran in, objects it added, its time per frame.
  int rescue_ran = 0, rescue_added = 0;
  std::vector<float> rescue_ms;
};
double Percent(int part, int whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

// The recall table of a run over several noise levels: what a camera's gain costs.
void PrintRecallAgainstNoise(const std::vector<float>& levels, const std::vector<Summary>& sums,
                             const ImageDegradation& degradation) {
  std::printf("\nrecall against noise (blur %.1f px, gain %.2f; correct and false as above):\n",
              degradation.blur_sigma_px, degradation.gain);
  std::printf("%8s %9s %9s %9s %9s %8s %8s %8s %9s\n", "noise", "correct", ">= 70 %", "40-70 %",
              "false", "t mm", "R deg", "med ms", "worst ms");
  for (size_t i = 0; i < levels.size(); ++i) {
    const Summary& sum = sums[i];
    const Row& t = sum.total;
    std::printf("%8.1f %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.3f %8.3f %8.1f %9.1f\n", levels[i],
                Percent(t.correct, t.objects), Percent(sum.vis_correct[2], sum.vis_objects[2]),
                Percent(sum.vis_correct[1], sum.vis_objects[1]),
                Percent(t.false_alarms, t.correct + t.false_alarms), Median(t.t_err_mm),
                Median(t.r_err_deg), Median(t.time_ms), Max(t.time_ms));
  }
}

// One level of that table for the JSON: {"noise_sigma", "objects", "correct", ...}.
std::string NoiseLevelJson(float level, const Summary& sum) {
  const Row& t = sum.total;
  char buffer[768];
  std::snprintf(buffer, sizeof(buffer),
                "{\"noise_sigma\": %.2f, \"objects\": %d, \"correct\": %d, \"false_alarms\": %d, "
                "\"correct_pct\": %.2f, \"false_alarm_pct\": %.2f, \"visible_70_pct\": %.2f, "
                "\"visible_40_70_pct\": %.2f, \"median_t_err_mm\": %.3f, "
                "\"median_r_err_deg\": %.3f, \"median_ms\": %.2f, \"worst_ms\": %.2f}",
                level, t.objects, t.correct, t.false_alarms, Percent(t.correct, t.objects),
                Percent(t.false_alarms, t.correct + t.false_alarms),
                Percent(sum.vis_correct[2], sum.vis_objects[2]),
                Percent(sum.vis_correct[1], sum.vis_objects[1]), Median(t.t_err_mm),
                Median(t.r_err_deg), Median(t.time_ms), Max(t.time_ms));
  return buffer;
}

int Fail(const char* message) {
  std::fprintf(stderr, "stereohash bench recorded: %s\n", message);
  return 1;
}

}  // namespace

int RunBenchRecorded(int argc, char** argv) {
  // argv[0] = "bench", argv[1] = "recorded", argv[2] = DIR.
  if (argc >= 3 && (std::strcmp(argv[2], "--help") == 0 || std::strcmp(argv[2], "-h") == 0)) {
    PrintHelp();
    return 0;
  }
  if (argc < 3 || argv[2][0] == '-') {
    std::fprintf(stderr,
                 "stereohash bench recorded: the scene folder DIR comes first (see --help)\n");
    return 2;
  }
  const std::string dir = argv[2];
  const char* json_path = nullptr;
  bool verbose = false, use_table_file = true, carry_table = false;
  RecognizeOptions options;
  std::vector<const char*> settings;       // --set name=value, for exploring settings
  std::vector<const char*> mono_settings;  // --set mono.name=value
  int mono_camera = -1;                    // --monocular left|right
  bool compare = false;
  float max_t_mm = kMaxPositionErrorMm, max_r_deg = kMaxRotationErrorDeg;
  int64_t (*clock)() = NowNs;    // --cpu-time: this process's CPU time instead
  ImageDegradation degradation;  // --noise (one level at a time), --blur, --gain
  std::vector<float> noise_levels = {0.0f};
  for (int i = 3; i < argc; ++i) {
    if (std::strcmp(argv[i], "--verbose") == 0) {
      verbose = true;
      continue;
    }
    if (std::strcmp(argv[i], "--no-table") == 0) {
      use_table_file = false;
      continue;
    }
    if (std::strcmp(argv[i], "--carry-table") == 0) {
      carry_table = true;
      continue;
    }
    if (std::strcmp(argv[i], "--compare") == 0) {
      compare = true;
      continue;
    }
    if (std::strcmp(argv[i], "--cpu-time") == 0) {
      clock = CpuNs;
      continue;
    }
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("bench recorded", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    if (std::strcmp(arg, "--json") == 0) {
      json_path = value;
      continue;
    }
    if (std::strcmp(arg, "--set") == 0) {
      (std::strncmp(value, "mono.", 5) == 0 ? mono_settings : settings).push_back(value);
      continue;
    }
    if (std::strcmp(arg, "--tolerance") == 0) {
      if (std::sscanf(value, "%f,%f", &max_t_mm, &max_r_deg) != 2 || !(max_t_mm > 0) ||
          !(max_r_deg > 0)) {
        std::fprintf(stderr, "stereohash bench recorded: --tolerance needs MM,DEG\n");
        return 2;
      }
      continue;
    }
    if (std::strcmp(arg, "--noise") == 0) {
      if (!ParseNoiseLevels(value, &noise_levels)) {
        std::fprintf(stderr,
                     "stereohash bench recorded: --noise needs SIGMA[,SIGMA...], each 0..64 grey "
                     "levels, got '%s'\n",
                     value);
        return 2;
      }
      continue;
    }
    if (std::strcmp(arg, "--blur") == 0 || std::strcmp(arg, "--gain") == 0) {
      char* end = nullptr;
      const float v = std::strtof(value, &end);
      (arg[2] == 'b' ? degradation.blur_sigma_px : degradation.gain) = v;
      const Status valid = ValidateDegradation(degradation);
      if (end == value || *end != '\0' || !valid.ok()) {
        std::fprintf(stderr, "stereohash bench recorded: %s '%s': %s\n", arg, value,
                     valid.ok() ? "not a number" : valid.message());
        return 2;
      }
      continue;
    }
    if (std::strcmp(arg, "--monocular") == 0) {
      if (std::strcmp(value, "left") != 0 && std::strcmp(value, "right") != 0) {
        std::fprintf(stderr, "stereohash bench recorded: --monocular is left or right\n");
        return 2;
      }
      mono_camera = value[0] == 'l' ? 0 : 1;
      continue;
    }
    const OptionResult common = ParseRecognizeOption("bench recorded", arg, value, &options);
    if (common == OptionResult::kBadValue) return 2;
    if (common == OptionResult::kNotMine) {
      std::fprintf(stderr, "stereohash bench recorded: unknown option %s (see --help)\n", arg);
      return 2;
    }
  }
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());

  const Result<StereoCalibration> calib = LoadFrameCalibration((dir + "/calib.yaml").c_str());
  if (!calib.ok()) return Fail(calib.status().message());
  TableChoice table;
  std::string table_path;
  if (options.table_path != nullptr) {
    table_path = options.table_path;
  } else if (use_table_file && IsFile(dir + "/table.yaml")) {
    table_path = dir + "/table.yaml";
  }
  if (!table_path.empty()) {
    const Result<RigidTransform> pose = LoadTablePose(table_path.c_str());
    if (!pose.ok()) return Fail(pose.status().message());
    table.present = true;
    table.left_T_table = *pose;
    table.source = table_path;
  }
  // The set's table.yaml, also under --no-table: the estimated table is compared with it.
  bool have_reference = false;
  RigidTransform reference;
  if (IsFile(dir + "/table.yaml")) {
    const Result<RigidTransform> pose = LoadTablePose((dir + "/table.yaml").c_str());
    if (!pose.ok()) return Fail(pose.status().message());
    have_reference = true;
    reference = *pose;
  }
  LoadedTables tables;
  Status s = LoadTables(options, &tables);
  if (!s.ok()) return Fail(s.message());
  std::vector<Model> models;
  const ModelSet model_set = tables.models();
  for (uint32_t m = 0; m < model_set.count(); ++m) models.push_back(model_set.model(m));

  const std::vector<std::string> scenes = SceneFolders(dir);
  if (scenes.empty()) {
    return Fail(("no scene folders (with left.png, right.png, truth.json) in " + dir).c_str());
  }
  if (compare && noise_levels.size() > 1) {
    std::fprintf(stderr, "stereohash bench recorded: --compare takes one --noise level\n");
    return 2;
  }
  if ((mono_camera >= 0 || compare) && !table.present) {
    std::fprintf(stderr,
                 "stereohash bench recorded: %s: the set has no table.yaml, or --no-table was "
                 "given\n",
                 kMonoNeedsTablePlane);
    return 2;
  }
  if (carry_table && noise_levels.size() > 1) {
    std::fprintf(stderr,
                 "stereohash bench recorded: --carry-table runs the scenes as one cell's frames; "
                 "give one --noise level with it\n");
    return 2;
  }
  if (carry_table && table.present) {
    std::fprintf(stderr,
                 "stereohash bench recorded: --carry-table carries the estimated plane, but the "
                 "table of %s is given (add --no-table)\n",
                 table.source.c_str());
    return 2;
  }
  PipelineConfig config = MakePipelineConfig(options, table);
  config.table_carry.enabled = carry_table;
  for (const char* setting : settings) {
    if (const Status applied = ApplyPipelineSetting(setting, &config); !applied.ok()) {
      std::fprintf(stderr, "stereohash bench recorded: %s\n", applied.message());
      return 2;
    }
  }
  // The systems to run: the stereo pipeline, the monocular mode, or both side by side.
  const bool run_stereo = mono_camera < 0 || compare;
  const bool run_mono = mono_camera >= 0 || compare;
  const int camera = mono_camera >= 0 ? mono_camera : 0;
  std::unique_ptr<Pipeline> pipeline;
  if (run_stereo) {
    pipeline = std::make_unique<Pipeline>();
    s = pipeline->Init(*calib, tables.view, config, clock, tables.shape());
    if (!s.ok()) return Fail(s.message());
  }
  // A second recogniser with the pipeline's settings, for the search's view of the misses.
  std::unique_ptr<Recognizer> search;
  if (run_stereo && (verbose || json_path != nullptr) && model_set.hash_count() > 0) {
    search = std::make_unique<Recognizer>();
    s = search->Init(tables.view, config.recognizer);
    if (!s.ok()) return Fail(s.message());
  }
  SearchTrace trace;
  if (run_stereo) pipeline->SetSearchObserver(&trace);
  LoadedAspects aspects;
  std::unique_ptr<MonoPipeline> mono;
  ZeroedPtr<FeatureWorkspace> workspace;
  // The stereo pipeline's one-image rescue (PipelineConfig::rescue) and the monocular mode both
  // need the aspect table and the one-camera settings.
  const bool rescue = run_stereo && config.rescue.enabled && model_set.hash_count() > 0;
  ZeroedPtr<MonoRecognizer> rescue_recognizer;
  MonoPipelineConfig mono_config = MakeMonoConfig(options);
  if (run_mono || rescue) {
    s = LoadAspects(options, &aspects);
    if (!s.ok()) return Fail(s.message());
    // Poses are scored by model index: both tables must list the same models in order.
    bool same = aspects.view.model_count() == tables.view.model_count();
    for (uint32_t m = 0; same && m < tables.view.model_count(); ++m) {
      same = std::strcmp(aspects.view.model(m).name, tables.view.model(m).name) == 0;
    }
    if (!same) return Fail("the aspect table's models differ from the hash tables'");
    for (const char* setting : mono_settings) {
      if (const Status applied = ApplyMonoSetting(setting, &mono_config); !applied.ok()) {
        std::fprintf(stderr, "stereohash bench recorded: %s\n", applied.message());
        return 2;
      }
    }
  }
  if (rescue) {
    s = LendRescueRecognizer(aspects.view, *calib, table.present ? &table.left_T_table : nullptr,
                             mono_config.mono, pipeline.get(), &rescue_recognizer);
    if (!s.ok()) return Fail(s.message());
  }
  if (run_mono) {
    mono = std::make_unique<MonoPipeline>();
    workspace = MakeWorkspace<FeatureWorkspace>();  // any image size up to the maximum
    s = mono->Init(*calib, camera, aspects.view, table.present ? &table.left_T_table : nullptr,
                   mono_config, clock);
    if (!s.ok()) return Fail(s.message());
  }

  // One system over every scene: prints its table and fills its summary.

  auto run = [&](bool monocular, Summary* sum) -> Status {
    std::vector<Row> rows;
    auto result = std::make_unique<PipelineResult>();
    auto mono_result = std::make_unique<MonoResult>();
    LoadedImage left, right;
    for (const std::string& name : scenes) {
      const std::string base = SceneFolderPath(dir, name);
      SceneTruth truth;
      Status st = ParseTruth(base + "truth.json", model_set, &truth);
      if (st.ok() && (!monocular || camera == 0)) {
        st = LoadImage((base + "left.png").c_str(), "left", &left);
        if (st.ok()) st = DegradeLoaded(degradation, DegradationSeed(name.c_str(), 0), &left);
      }
      if (st.ok() && (!monocular || camera == 1)) {
        st = LoadImage((base + "right.png").c_str(), "right", &right);
        if (st.ok()) st = DegradeLoaded(degradation, DegradationSeed(name.c_str(), 1), &right);
      }
      if (st.ok() && !monocular) {
        trace.Clear();
        st = pipeline->Process(left.frame, right.frame, options.budget_ms, result.get());
      }
      if (st.ok() && monocular) {
        st = mono->Process(camera == 0 ? left.view : right.view, options.budget_ms, *workspace,
                           mono_result.get());
      }
      if (!st.ok()) return Status::Error(st.code(), "%s: %s", name.c_str(), st.message());
      const Vector<RecognizedObject>& objects =
          monocular ? static_cast<const Vector<RecognizedObject>&>(mono_result->objects)
                    : static_cast<const Vector<RecognizedObject>&>(result->objects);
      std::vector<RecognizedPose> found;
      for (const RecognizedObject& o : objects) found.push_back({o.model, o.cam_T_model});
      const MatchCounts m = MatchToTruth(models, truth.objects, found, max_t_mm, max_r_deg);
      auto it = std::find_if(rows.begin(), rows.end(), [&](const Row& r) {
        return r.background == truth.background && r.occlusion == truth.occlusion;
      });
      if (it == rows.end()) {
        rows.push_back(Row{});
        it = rows.end() - 1;
        it->background = truth.background;
        it->occlusion = truth.occlusion;
      }
      Row& row = *it;
      ++row.scenes;
      row.objects += static_cast<int>(truth.objects.size());
      row.correct += m.correct;
      row.missed += m.missed;
      row.false_alarms += m.false_alarms;
      row.t_err_mm.insert(row.t_err_mm.end(), m.translation_errors_mm.begin(),
                          m.translation_errors_mm.end());
      row.r_err_deg.insert(row.r_err_deg.end(), m.rotation_errors_deg.begin(),
                           m.rotation_errors_deg.end());
      float total_ms;
      if (monocular) {
        total_ms = mono_result->time.total_ms;
        row.features_ms.push_back(mono_result->time.features_ms);
        row.hashing_ms.push_back(mono_result->time.recognition_ms);
        row.points2d.push_back(float(mono_result->points2d));
        row.lines2d.push_back(float(mono_result->lines2d));
      } else {
        // The poses before the final edge fit, for its effect on the errors.
        std::vector<RecognizedPose> feature_poses;
        for (const RecognizedObject& o : result->objects) {
          feature_poses.push_back({o.model, o.cam_T_model_features});
        }
        const MatchCounts mf =
            MatchToTruth(models, truth.objects, feature_poses, max_t_mm, max_r_deg);
        row.feature_t_err_mm.insert(row.feature_t_err_mm.end(), mf.translation_errors_mm.begin(),
                                    mf.translation_errors_mm.end());
        row.feature_r_err_deg.insert(row.feature_r_err_deg.end(), mf.rotation_errors_deg.begin(),
                                     mf.rotation_errors_deg.end());
        total_ms = result->time.total_ms;
        row.features_ms.push_back(result->time.features_ms);
        row.stereo_ms.push_back(result->time.stereo_ms);
        row.hashing_ms.push_back(result->time.hashing_ms);
        row.verify_ms.push_back(result->time.verify_ms);
        row.scene_bases_tried += result->recognition.scene_bases_tried;
        row.points2d.push_back(float(result->points2d[0] + result->points2d[1]) * 0.5f);
        row.lines2d.push_back(float(result->lines2d[0] + result->lines2d[1]) * 0.5f);
        row.points3d.push_back(float(result->points3d));
        row.lines3d.push_back(float(result->lines3d));
      }
      row.time_ms.push_back(total_ms);
      std::string table_json;
      if (!monocular) {
        table_json = std::string("\"table\": \"") + TableSourceName(result->table_source) + "\", ";
        const TableEstimate& e = result->table_estimate;
        const TableCarry& carry = result->table_carry;
        if (config.table_carry.enabled) {
          if (result->table_source == TableSource::kCarried) ++sum->carried;
          sum->drops = static_cast<int>(carry.drops());
          char buffer[200];
          std::snprintf(buffer, sizeof(buffer),
                        "\"table_carry\": {\"state\": \"%s\", \"agreeing\": %u, \"misfits\": %u, "
                        "\"resting\": %u, \"drops\": %u}, ",
                        TableCarryStateName(carry.state()), carry.agreeing(), carry.misfits(),
                        result->table_resting, carry.drops());
          table_json += buffer;
          if (verbose) {
            std::printf("%s: table %s; carry %s, %u agreeing, %u misfits, %u of %zu resting\n",
                        name.c_str(), TableSourceName(result->table_source),
                        TableCarryStateName(carry.state()), carry.agreeing(), carry.misfits(),
                        result->table_resting, result->objects.size());
          }
        }
        if (e.outcome != TableEstimateOutcome::kDisabled) {
          ++sum->estimates;
          sum->table_ms.push_back(result->time.table_ms);
          float normal_err = -1, offset_err = 0;
          if (have_reference) {
            // Angle between the normals; height of the reference origin over the estimated plane.
            const Eigen::Vector3f n = e.left_T_table.R.col(2);
            normal_err = std::acos(std::min(1.0f, n.dot(reference.R.col(2)))) * 57.29578f;
            offset_err = n.dot(reference.t_mm - e.left_T_table.t_mm);
          }
          if (e.accepted()) {
            ++sum->estimates_accepted;
            if (have_reference) {
              sum->normal_err_deg.push_back(normal_err);
              sum->offset_err_mm.push_back(std::fabs(offset_err));
            }
          }
          char buffer[320];
          std::snprintf(buffer, sizeof(buffer),
                        "\"table_estimate\": {\"outcome\": \"%s\", \"objects\": %u, "
                        "\"resting\": %u, \"rms_mm\": %.3f, \"dropped\": %u, "
                        "\"normal_err_deg\": %.3f, \"offset_mm\": %.2f}, ",
                        TableEstimateOutcomeName(e.outcome), e.objects, e.resting, e.rms_mm,
                        result->table_dropped, normal_err, offset_err);
          table_json += buffer;
          if (verbose) {
            std::printf(
                "%s: table estimate %s: %u of %u objects rest on it, rms %.2f mm, %u "
                "features dropped",
                name.c_str(), TableEstimateOutcomeName(e.outcome), e.resting, e.objects, e.rms_mm,
                result->table_dropped);
            if (have_reference && e.accepted()) {
              std::printf("; against table.yaml %.2f deg, %.2f mm", normal_err, offset_err);
            }
            std::printf("\n");
          }
        }
      }
      for (size_t i = 0; i < truth.objects.size(); ++i) {
        const int bin = VisibilityBin(truth.visible[i]);
        ++sum->vis_objects[bin];
        sum->vis_correct[bin] += m.truth_found[i] ? 1 : 0;
      }
      if (!monocular) {
        const RescueStats& rs = result->rescue;
        sum->rescue_ran += rs.ran ? 1 : 0;
        sum->rescue_added += static_cast<int>(rs.added);
        sum->rescue_ms.push_back(result->time.rescue_ms);
      }
      if (verbose) {
        std::printf("%s: %d of %zu correct, %d false, %.1f ms\n", name.c_str(), m.correct,
                    truth.objects.size(), m.false_alarms, total_ms);
        if (!monocular && result->rescue.ran) {
          const RescueStats& rs = result->rescue;
          std::printf(
              "  rescue: %u / %u free corners, %u / %u bases tried (left / right image), found "
              "%u, refused %u resting, %u verify, %u overlap; added %u (%.1f ms)\n",
              rs.free_corners, rs.free_corners_right, rs.search.scene_bases_tried,
              rs.search_right.scene_bases_tried, rs.found, rs.refused_rest, rs.refused_verify,
              rs.refused_overlap, rs.added, result->time.rescue_ms);
        }
        if (!monocular && model_set.shape_count() > 0) {
          const ShapeStats& sh = result->shape;
          std::printf(
              "  shape path: regions %u / %u, blobs %u / %u, pairs %u, mono %u, hypotheses %u, "
              "verified %u; segment %.1f, search %.1f, refine %.1f, verify %.1f ms\n",
              sh.regions[0], sh.regions[1], sh.blobs[0], sh.blobs[1], sh.pairs, sh.mono_seeds,
              sh.hypotheses, sh.verified, sh.time.segment_ms, sh.time.search_ms, sh.time.refine_ms,
              sh.time.verify_ms);
        }
      }
      std::string false_json;
      for (const RecognizedObject& o : objects) {
        const std::vector<RecognizedPose> one = {{o.model, o.cam_T_model}};
        if (MatchToTruth(models, truth.objects, one, max_t_mm, max_r_deg).correct == 1) continue;
        if (verbose) {
          std::printf("  %s: false %s at (%.1f, %.1f, %.1f) mm (vote %.2f, verify %.2f %.2f)\n",
                      name.c_str(), models[o.model].name, o.cam_T_model.t_mm.x(),
                      o.cam_T_model.t_mm.y(), o.cam_T_model.t_mm.z(), o.vote, o.verify_score[0],
                      o.verify_score[1]);
        }
        char model_name[kJsonNameBytes];
        char buffer[256 + kJsonNameBytes];
        std::snprintf(
            buffer, sizeof(buffer),
            "%s{\"model\": \"%s\", \"t\": [%.2f, %.2f, %.2f], \"vote\": %.3f, "
            "\"verify\": [%.3f, %.3f]}",
            false_json.empty() ? "" : ", ",
            JsonEscaped(models[o.model].name, sizeof(Model::name), model_name, sizeof(model_name)),
            o.cam_T_model.t_mm.x(), o.cam_T_model.t_mm.y(), o.cam_T_model.t_mm.z(), o.vote,
            o.verify_score[0], o.verify_score[1]);
        false_json += buffer;
      }
      std::vector<MissRecord> misses;
      if (monocular) {
        ExplainMonoMisses(models, truth.objects, mono_result->objects, mono->features(),
                          mono->recognizer(), name.c_str(), verbose, sum->mono_causes, max_t_mm,
                          max_r_deg);
      } else {
        ExplainMisses(models, truth.objects, *result, *pipeline, name.c_str(), verbose,
                      &sum->causes, max_t_mm, max_r_deg, &misses, search.get(), &trace);
      }
      std::string missed_json;
      for (const MissRecord& miss : misses) {
        const Model& model = models[truth.objects[miss.truth_index].model];
        char model_name[kJsonNameBytes];
        char lost_to[kJsonNameBytes];
        char buffer[1024 + 2 * kJsonNameBytes];
        std::snprintf(buffer, sizeof(buffer),
                      "%s{\"model\": \"%s\", \"visible\": %.3f, \"cause\": \"%s\", "
                      "\"verify_at_truth\": [%.3f, %.3f], \"support_at_truth\": %.3f, "
                      "\"own_bases\": %d, \"first_own_rank\": %d, \"good_bases\": %d, "
                      "\"first_good_rank\": %d, \"candidates\": %d, \"near_hypotheses\": %d, "
                      "\"refined_close\": %d, \"too_close\": %d, \"rejected\": %d, "
                      "\"verified\": %d, \"lost_to\": \"%s\", \"edges\": [%d, %d, %d, %d], "
                      "\"corners\": [%d, %d, %d, %d], \"edges_2d_both\": %d, "
                      "\"edges_lost_stereo\": %d, \"edges_lost_epipolar\": %d}",
                      missed_json.empty() ? "" : ", ",
                      JsonEscaped(model.name, sizeof(model.name), model_name, sizeof(model_name)),
                      truth.visible[miss.truth_index], miss.cause, miss.verify_score[0],
                      miss.verify_score[1], miss.support, miss.own_bases, miss.first_own_rank,
                      miss.good_bases, miss.first_good_rank, miss.candidates, miss.near_hypotheses,
                      miss.refined_close, miss.too_close, miss.rejected, miss.verified,
                      JsonEscaped(miss.lost_to, sizeof(Model::name), lost_to, sizeof(lost_to)),
                      miss.edges_visible, miss.edges_2d[0], miss.edges_2d[1], miss.edges_3d,
                      miss.corners_visible, miss.corners_2d[0], miss.corners_2d[1], miss.corners_3d,
                      miss.edges_2d_both, miss.edges_lost_stereo, miss.edges_lost_epipolar);
        missed_json += buffer;
      }
      char buffer[512];
      std::snprintf(buffer, sizeof(buffer),
                    "%s\n    {\"scene\": \"%s\", \"background\": \"%s\", \"occlusion\": \"%s\", "
                    "\"objects\": %zu, \"correct\": %d, \"false_alarms\": %d, \"total_ms\": %.2f, ",
                    sum->scene_json.empty() ? "" : ",", name.c_str(), truth.background.c_str(),
                    truth.occlusion.c_str(), truth.objects.size(), m.correct, m.false_alarms,
                    total_ms);
      sum->scene_json += buffer;
      if (!monocular) {
        std::snprintf(buffer, sizeof(buffer),
                      "\"points3d\": %u, \"lines3d\": %u, \"scene_bases_tried\": %u, "
                      "\"rescue\": {\"ran\": %s, \"ran_right\": %s, \"found\": %u, "
                      "\"added\": %u, \"ms\": %.2f}, ",
                      result->points3d, result->lines3d, result->recognition.scene_bases_tried,
                      result->rescue.ran ? "true" : "false",
                      result->rescue.ran_right ? "true" : "false", result->rescue.found,
                      result->rescue.added, result->time.rescue_ms);
        sum->scene_json += buffer;
      }
      sum->scene_json += table_json;
      sum->scene_json.append("\"missed\": [").append(missed_json);
      sum->scene_json.append("], \"false\": [").append(false_json).append("]}");
    }

    if (monocular) {
      std::printf(
          "\nRecorded scenes %s, monocular (%s images): %zu scenes; correct = same model, "
          "within %.0f mm and %.0f deg (symmetry-aware);\n2-D counts per image, counts and "
          "times medians over the row; pose errors medians over the correct objects; table: "
          "%s.\n\n",
          dir.c_str(), camera == 0 ? "left" : "right", scenes.size(), max_t_mm, max_r_deg,
          table.present ? table.source.c_str() : "none");
    } else {
      std::printf(
          "\nRecorded scenes %s: %zu scenes; correct = same model, within %.0f mm and %.0f deg "
          "(symmetry-aware);\n2-D counts per image (mean of left and right), counts and times "
          "medians over the row; pose errors\nmedians over the correct objects; table: %s; %d "
          "thread%s.\n\n",
          dir.c_str(), scenes.size(), max_t_mm, max_r_deg,
          table.present ? table.source.c_str() : "none", pipeline->threads(),
          pipeline->threads() == 1 ? "" : "s");
    }
    std::printf("%-6s %-7s %6s %7s %7s %6s %6s %8s %8s %6s %6s %6s %6s %7s %7s\n", "backgr",
                "occlus", "scenes", "objects", "correct", "missed", "false", "med ms", "worst ms",
                "2D pts", "2D lin", "3D pts", "3D lin", "t mm", "R deg");
    sum->total = Row{};
    sum->total.background = "all";
    for (const Row& row : rows) {
      PrintRow(row);
      sum->total.Add(row);
      sum->rows_json += (sum->rows_json.empty() ? "\n    " : ",\n    ") + RowJson(row);
    }
    const Row& total = sum->total;
    PrintRow(total);
    const int reported = total.correct + total.false_alarms;
    const double correct_pct = total.objects ? 100.0 * total.correct / total.objects : 0.0;
    const double false_pct = reported ? 100.0 * total.false_alarms / reported : 0.0;
    if (monocular) {
      std::printf(
          "\ncorrect %.1f %% of objects, false alarms %.1f %% of reported objects; median error "
          "%.2f mm / %.2f deg;\nframe median %.1f ms, worst %.1f ms; median stage times: "
          "features %.1f, recognition %.1f ms\n",
          correct_pct, false_pct, Median(total.t_err_mm), Median(total.r_err_deg),
          Median(total.time_ms), Max(total.time_ms), Median(total.features_ms),
          Median(total.hashing_ms));
    } else {
      std::printf(
          "\ncorrect %.1f %% of objects, false alarms %.1f %% of reported objects; median error "
          "%.2f mm / %.2f deg (feature refinement alone: %.2f mm / %.2f deg);\nframe median "
          "%.1f ms, worst %.1f ms; median stage times: features %.1f, stereo %.1f, hashing "
          "%.1f, verify %.1f ms\n",
          correct_pct, false_pct, Median(total.t_err_mm), Median(total.r_err_deg),
          Median(total.feature_t_err_mm), Median(total.feature_r_err_deg), Median(total.time_ms),
          Max(total.time_ms), Median(total.features_ms), Median(total.stereo_ms),
          Median(total.hashing_ms), Median(total.verify_ms));
    }
    if (!monocular && rescue) {
      std::printf(
          "rescue (one image, confirmed in both): ran in %d of %zu scenes, added %d "
          "objects; %.1f ms median, %.1f ms worst\n",
          sum->rescue_ran, scenes.size(), sum->rescue_added, Median(sum->rescue_ms),
          Max(sum->rescue_ms));
    }
    if (sum->estimates > 0) {
      std::printf("table estimated in %d of %d scenes, %.2f ms median, %.2f ms worst",
                  sum->estimates_accepted, sum->estimates, Median(sum->table_ms),
                  Max(sum->table_ms));
      if (!sum->normal_err_deg.empty()) {
        std::printf(
            "; against table.yaml: normal %.2f deg median, %.2f worst; offset %.2f mm "
            "median, %.2f worst",
            Median(sum->normal_err_deg), Max(sum->normal_err_deg), Median(sum->offset_err_mm),
            Max(sum->offset_err_mm));
      }
      std::printf("\n");
    }
    if (config.table_carry.enabled && !monocular) {
      std::printf("table carried in %d of %zu scenes, dropped %d times\n", sum->carried,
                  scenes.size(), sum->drops);
    }
    std::printf("recall by visibility:");
    for (int b = 0; b < kVisibilityBins; ++b) {
      std::printf("%s %s %d / %d (%.1f %%)", b ? "," : "", kVisibilityNames[b], sum->vis_correct[b],
                  sum->vis_objects[b],
                  sum->vis_objects[b] ? 100.0 * sum->vis_correct[b] / sum->vis_objects[b] : 0.0);
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer),
                    "%s{\"visible\": \"%s\", \"objects\": %d, \"correct\": %d}", b ? ", " : "",
                    kVisibilityNames[b], sum->vis_objects[b], sum->vis_correct[b]);
      sum->vis_json += buffer;
    }
    if (monocular) {
      std::printf(
          "\nmissed %d: at the true pose %d show under half of their corners and edges in the "
          "image's features, %d fail the image verification, %d were not found by the search\n",
          total.missed, sum->mono_causes[0], sum->mono_causes[1], sum->mono_causes[2]);
    } else {
      std::printf(
          "\nmissed %d: at the true pose %d fail the image verification (edges too weak or "
          "hidden), %d have under 30 %% 3-D support (stereo lost them), %d were not reached by "
          "the search\n",
          total.missed, sum->causes.no_edges, sum->causes.no_3d, sum->causes.not_searched);
      std::printf("scene bases tried %ld over %d scenes\n", total.scene_bases_tried, total.scenes);
    }
    return Status::Ok();
  };

  // One run per noise level; the first level's figures are the ones reported in full.
  Summary stereo_sum, mono_sum;
  std::vector<Summary> level_sums(noise_levels.size());
  for (size_t level = 0; level < noise_levels.size(); ++level) {
    degradation.noise_sigma = noise_levels[level];
    if (!degradation.none()) {
      std::printf("\n==== images degraded: noise sigma %.1f grey levels, blur %.1f px, gain %.2f\n",
                  degradation.noise_sigma, degradation.blur_sigma_px, degradation.gain);
    }
    Summary* stereo_out = level == 0 ? &stereo_sum : &level_sums[level];
    Summary* mono_out = level == 0 ? &mono_sum : &level_sums[level];
    if (run_stereo) {
      s = run(false, stereo_out);
      if (!s.ok()) return Fail(s.message());
    }
    if (run_mono) {
      s = run(true, mono_out);
      if (!s.ok()) return Fail(s.message());
    }
  }
  level_sums[0] = run_mono ? mono_sum : stereo_sum;
  if (noise_levels.size() > 1) PrintRecallAgainstNoise(noise_levels, level_sums, degradation);
  if (compare) {
    // Thesis 6.4.3: the 2-D system beside the 3-D one on the same scenes.
    std::printf("\nside by side (thesis ch. 6): %-8s %8s %8s %8s %10s %10s %10s\n", "", "correct",
                "false", "missed", "t err mm", "R err deg", "median ms");
    for (const auto& [label, sum] :
         {std::pair<const char*, const Summary*>{"stereo", &stereo_sum}, {"mono", &mono_sum}}) {
      const Row& t = sum->total;
      const int reported = t.correct + t.false_alarms;
      std::printf("                             %-8s %7.1f%% %7.1f%% %8d %10.2f %10.2f %10.1f\n",
                  label, t.objects ? 100.0 * t.correct / t.objects : 0.0,
                  reported ? 100.0 * t.false_alarms / reported : 0.0, t.missed, Median(t.t_err_mm),
                  Median(t.r_err_deg), Median(t.time_ms));
    }
  }

  if (json_path != nullptr) {
    auto system_json = [&](const Summary& sum, bool monocular) {
      const Row& total = sum.total;
      const int reported = total.correct + total.false_alarms;
      char summary[768];
      std::snprintf(
          summary, sizeof(summary),
          "\"summary\": {\"scenes\": %zu, \"objects\": %d, \"correct\": %d, \"missed\": %d, "
          "\"false_alarms\": %d, \"correct_pct\": %.2f, \"false_alarm_pct\": %.2f, "
          "\"median_t_err_mm\": %.3f, \"median_r_err_deg\": %.3f, "
          "\"feature_median_t_err_mm\": %.3f, \"feature_median_r_err_deg\": %.3f, "
          "\"median_ms\": %.2f, \"worst_ms\": %.2f, \"miss_causes\": %s}",
          scenes.size(), total.objects, total.correct, total.missed, total.false_alarms,
          total.objects ? 100.0 * total.correct / total.objects : 0.0,
          reported ? 100.0 * total.false_alarms / reported : 0.0, Median(total.t_err_mm),
          Median(total.r_err_deg), Median(total.feature_t_err_mm), Median(total.feature_r_err_deg),
          Median(total.time_ms), Max(total.time_ms),
          monocular ? ("{\"no_features\": " + std::to_string(sum.mono_causes[0]) +
                       ", \"no_edges\": " + std::to_string(sum.mono_causes[1]) +
                       ", \"not_found\": " + std::to_string(sum.mono_causes[2]) + "}")
                          .c_str()
                    : ("{\"no_edges\": " + std::to_string(sum.causes.no_edges) +
                       ", \"no_3d\": " + std::to_string(sum.causes.no_3d) +
                       ", \"not_searched\": " + std::to_string(sum.causes.not_searched) + "}")
                          .c_str());
      std::string json = std::string("  ") + summary + ",\n";
      json += "  \"visibility\": [" + sum.vis_json + "],\n";
      json += "  \"rows\": [" + sum.rows_json + "\n  ],\n";
      json += "  \"scenes\": [" + sum.scene_json + "\n  ]";
      return json;
    };
    std::string json = "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n";
    if (!degradation.none() || noise_levels.size() > 1) {
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer),
                    "  \"degradation\": {\"blur_sigma_px\": %.2f, \"gain\": %.3f},\n",
                    degradation.blur_sigma_px, degradation.gain);
      json += buffer;
      json += "  \"noise_levels\": [";
      for (size_t i = 0; i < noise_levels.size(); ++i) {
        json += (i ? ",\n    " : "\n    ") + NoiseLevelJson(noise_levels[i], level_sums[i]);
      }
      json += "\n  ],\n";
    }
    json += "  \"table\": \"" + (table.present ? table.source : std::string("none")) + "\",\n";
    if (compare) {
      json += "  \"stereo\": {\n" + system_json(stereo_sum, false) + "\n  },\n";
      json += "  \"monocular\": {\n" + system_json(mono_sum, true) + "\n  }\n}\n";
    } else {
      if (run_mono) json += "  \"mode\": \"monocular\",\n";
      json += system_json(run_mono ? mono_sum : stereo_sum, run_mono) + "\n}\n";
    }
    if (!WriteTextFile(json_path, json)) {
      std::fprintf(stderr, "stereohash bench recorded: cannot write %s\n", json_path);
      return 1;
    }
  }
  return 0;
}

}  // namespace sh::tools
