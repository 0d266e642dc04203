// `stereohash bench recorded DIR`: the pipeline, run exactly as `stereohash recognize` runs it,
// on every scene of a recorded set (DIR/calib.yaml, DIR/table.yaml, DIR/sceneNN/{left.png,
// right.png, truth.json}; format in docs/pipeline.md), scored against the truth: thesis table
// 5.5 per background x occlusion row, recall by visibility, false alarms, pose errors, frame
// times, and why each missed object was missed at its true pose.
#include "tools/bench_recorded.hpp"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "recog/base/printable.hpp"
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tools/bench_recognizer.hpp"
#include "tools/bench_scoring.hpp"
#include "tools/command.hpp"
#include "tools/eval/image_degrade.hpp"
#include "tools/eval/mini_json.hpp"
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

// The command line.
struct BenchOptions {
  std::string dir;
  const char* json_path = nullptr;
  bool verbose = false, use_table_file = true, carry_table = false;
  bool compare = false;  // the stereo pipeline and the monocular mode side by side
  RecognizeOptions options;
  std::vector<const char*> settings;       // --set name=value, for exploring settings
  std::vector<const char*> mono_settings;  // --set mono.name=value
  int mono_camera = -1;                    // --monocular left|right
  float max_t_mm = kMaxPositionErrorMm, max_r_deg = kMaxRotationErrorDeg;
  int64_t (*clock)() = NowNs;    // --cpu-time: this process's CPU time instead
  ImageDegradation degradation;  // --noise (one level at a time), --blur, --gain
  std::vector<float> noise_levels = {0.0f};
};

// A flag of the command (no value); false: not one of them.
bool TakeFlag(const char* arg, BenchOptions* o) {
  if (std::strcmp(arg, "--verbose") == 0) {
    o->verbose = true;
  } else if (std::strcmp(arg, "--no-table") == 0) {
    o->use_table_file = false;
  } else if (std::strcmp(arg, "--carry-table") == 0) {
    o->carry_table = true;
  } else if (std::strcmp(arg, "--compare") == 0) {
    o->compare = true;
  } else if (std::strcmp(arg, "--cpu-time") == 0) {
    o->clock = CpuNs;
  } else {
    return false;
  }
  return true;
}

// --blur SIGMA or --gain G, checked as a whole degradation.
bool TakeDegradation(const char* arg, const char* value, ImageDegradation* degradation) {
  char* end = nullptr;
  const float v = std::strtof(value, &end);
  (arg[2] == 'b' ? degradation->blur_sigma_px : degradation->gain) = v;
  const Status valid = ValidateDegradation(*degradation);
  if (end == value || *end != '\0' || !valid.ok()) {
    std::fprintf(stderr, "stereohash bench recorded: %s '%s': %s\n", arg, value,
                 valid.ok() ? "not a number" : valid.message());
    return false;
  }
  return true;
}

// The options of this command with a value: kBadValue has said why.
OptionResult TakeBenchOption(const char* arg, const char* value, BenchOptions* o) {
  if (std::strcmp(arg, "--json") == 0) {
    o->json_path = value;
  } else if (std::strcmp(arg, "--set") == 0) {
    (std::strncmp(value, "mono.", 5) == 0 ? o->mono_settings : o->settings).push_back(value);
  } else if (std::strcmp(arg, "--tolerance") == 0) {
    if (std::sscanf(value, "%f,%f", &o->max_t_mm, &o->max_r_deg) != 2 || !(o->max_t_mm > 0) ||
        !(o->max_r_deg > 0)) {
      std::fprintf(stderr, "stereohash bench recorded: --tolerance needs MM,DEG\n");
      return OptionResult::kBadValue;
    }
  } else if (std::strcmp(arg, "--noise") == 0) {
    if (!ParseNoiseLevels(value, &o->noise_levels)) {
      std::fprintf(stderr,
                   "stereohash bench recorded: --noise needs SIGMA[,SIGMA...], each 0..64 grey "
                   "levels, got '%s'\n",
                   value);
      return OptionResult::kBadValue;
    }
  } else if (std::strcmp(arg, "--blur") == 0 || std::strcmp(arg, "--gain") == 0) {
    if (!TakeDegradation(arg, value, &o->degradation)) return OptionResult::kBadValue;
  } else if (std::strcmp(arg, "--monocular") == 0) {
    if (std::strcmp(value, "left") != 0 && std::strcmp(value, "right") != 0) {
      std::fprintf(stderr, "stereohash bench recorded: --monocular is left or right\n");
      return OptionResult::kBadValue;
    }
    o->mono_camera = value[0] == 'l' ? 0 : 1;
  } else {
    return ParseRecognizeOption("bench recorded", arg, value, &o->options);
  }
  return OptionResult::kTaken;
}

// The options after DIR; -1 to go on, else the exit code.
int ParseOptions(int argc, char** argv, BenchOptions* o) {
  for (int i = 3; i < argc; ++i) {
    if (TakeFlag(argv[i], o)) continue;
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("bench recorded", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    const OptionResult taken = TakeBenchOption(arg, value, o);
    if (taken == OptionResult::kBadValue) return 2;
    if (taken == OptionResult::kNotMine) {
      std::fprintf(stderr, "stereohash bench recorded: unknown option %s (see --help)\n", arg);
      return 2;
    }
  }
  return -1;
}

// The recorded set: its calibration, table poses, model set and scene folders.
struct RecordedSet {
  StereoCalibration calib;
  TableChoice table;  // the table recognition is told of (--table, else DIR/table.yaml)
  bool have_reference = false;
  RigidTransform reference;  // DIR/table.yaml, also under --no-table: estimates are scored on it
  LoadedTables tables;
  std::vector<Model> models;  // the model set's, by model index
  std::vector<std::string> scenes;
};

// The table recognition is told of, and the set's own for scoring the estimated table.
Status LoadTablePoses(const BenchOptions& o, RecordedSet* set) {
  std::string table_path;
  if (o.options.table_path != nullptr) {
    table_path = o.options.table_path;
  } else if (o.use_table_file && IsFile(o.dir + "/table.yaml")) {
    table_path = o.dir + "/table.yaml";
  }
  if (!table_path.empty()) {
    const Result<RigidTransform> pose = LoadTablePose(table_path.c_str());
    if (!pose.ok()) return pose.status();
    set->table.present = true;
    set->table.left_T_table = *pose;
    set->table.source = table_path;
  }
  if (IsFile(o.dir + "/table.yaml")) {
    const Result<RigidTransform> pose = LoadTablePose((o.dir + "/table.yaml").c_str());
    if (!pose.ok()) return pose.status();
    set->have_reference = true;
    set->reference = *pose;
  }
  return Status::Ok();
}

Status LoadSet(const BenchOptions& o, RecordedSet* set) {
  const Result<StereoCalibration> calib = LoadFrameCalibration((o.dir + "/calib.yaml").c_str());
  if (!calib.ok()) return calib.status();
  set->calib = *calib;
  SH_RETURN_IF_ERROR(LoadTablePoses(o, set));
  SH_RETURN_IF_ERROR(LoadTables(o.options, &set->tables));
  const ModelSet model_set = set->tables.models();
  for (uint32_t m = 0; m < model_set.count(); ++m) set->models.push_back(model_set.model(m));
  set->scenes = SceneFolders(o.dir);
  if (set->scenes.empty()) {
    return Status::Error(StatusCode::kNotFound,
                         "no scene folders (with left.png, right.png, truth.json) in %s",
                         o.dir.c_str());
  }
  return Status::Ok();
}

// The combinations of options that cannot run; prints why and returns false.
bool ModesAgree(const BenchOptions& o, const RecordedSet& set) {
  const char* refusal = nullptr;
  if (o.compare && o.noise_levels.size() > 1) {
    refusal = "--compare takes one --noise level";
  } else if ((o.mono_camera >= 0 || o.compare) && !set.table.present) {
    std::fprintf(stderr,
                 "stereohash bench recorded: %s: the set has no table.yaml, or --no-table was "
                 "given\n",
                 kMonoNeedsTablePlane);
    return false;
  } else if (o.carry_table && o.noise_levels.size() > 1) {
    refusal = "--carry-table runs the scenes as one cell's frames; give one --noise level with it";
  } else if (o.carry_table && set.table.present) {
    std::fprintf(stderr,
                 "stereohash bench recorded: --carry-table carries the estimated plane, but the "
                 "table of %s is given (add --no-table)\n",
                 set.table.source.c_str());
    return false;
  }
  if (refusal != nullptr) std::fprintf(stderr, "stereohash bench recorded: %s\n", refusal);
  return refusal == nullptr;
}

// What recognises the scenes: the facade on the tuned settings, and the diagnostics beside it.
struct BenchSystems {
  // The systems to run: the stereo pipeline, the monocular mode, or both side by side.
  bool run_stereo = true, run_mono = false;
  int camera = 0;  // of the monocular mode
  PipelineConfig config;
  MonoPipelineConfig mono_config;
  BenchRecognizer facade;
  // A second recogniser with the pipeline's settings, for the search's view of the misses.
  std::unique_ptr<Recognizer> search;
  SearchTrace trace;  // every hypothesis of the frame's stereo search
};

// The preset with the --set settings; false when one is not known (said).
bool TuneConfigs(const BenchOptions& o, const RecordedSet& set, BenchSystems* sys) {
  sys->config = MakePipelineConfig(o.options, set.table);
  sys->config.table_carry.enabled = o.carry_table;
  sys->mono_config = MakeMonoConfig(o.options);
  Status applied = Status::Ok();
  for (const char* setting : o.settings) {
    if (applied.ok()) applied = ApplyPipelineSetting(setting, &sys->config);
  }
  for (const char* setting : o.mono_settings) {
    if (applied.ok()) applied = ApplyMonoSetting(setting, &sys->mono_config);
  }
  if (!applied.ok()) std::fprintf(stderr, "stereohash bench recorded: %s\n", applied.message());
  return applied.ok();
}

// The facade set up for the set (its table, if any, also the monocular mode's), its search
// observed, and the misses' recogniser.
Status SetUpSystems(const BenchOptions& o, const RecordedSet& set, BenchSystems* sys) {
  sys->run_stereo = o.mono_camera < 0 || o.compare;
  sys->run_mono = o.mono_camera >= 0 || o.compare;
  sys->camera = o.mono_camera >= 0 ? o.mono_camera : 0;
  ObjectRecognizerConfig config = TunedRecognizerConfig(sys->config, sys->mono_config, o.clock);
  config.mono_table_known = set.table.present;
  config.aspects_file =
      o.options.aspects_path != nullptr ? o.options.aspects_path : o.options.tables_path;
  SH_RETURN_IF_ERROR(MakeBenchRecognizer(config, &sys->facade));
  ObjectRecognizer& recognizer = *sys->facade.recognizer;
  SH_RETURN_IF_ERROR(recognizer.Init(set.calib, set.tables.models(), ~0u));
  // Poses are scored by model index: both tables must list the same models in order.
  if (sys->run_mono && !SameModels(recognizer.aspects(), set.tables.view)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "the aspect table's models differ from the hash tables'");
  }
  if (!sys->run_stereo) return Status::Ok();
  recognizer.SetSearchObserver(&sys->trace);
  if ((o.verbose || o.json_path != nullptr) && set.tables.models().hash_count() > 0) {
    sys->search = std::make_unique<Recognizer>();
    SH_RETURN_IF_ERROR(
        sys->search->Init(set.tables.view, recognizer.pipeline().config().recognizer));
  }
  return Status::Ok();
}

// The figures of one system (stereo or monocular) over every scene of the set.
struct Summary {
  ScoreRow total;
  MissTally misses;
  int vis_objects[kVisibilityBins] = {}, vis_correct[kVisibilityBins] = {};
  std::string rows_json, scene_json, vis_json;
  // Table estimates: made, accepted, their errors against DIR/table.yaml, their time.
  int estimates = 0, estimates_accepted = 0;
  // Frames that took the carried plane, and planes dropped (--carry-table).
  int carried = 0, drops = 0;
  std::vector<float> normal_err_deg, offset_err_mm, table_ms;
  RescueTally rescue;
};

// Everything one run over the scenes reads.
struct RecordedBench {
  BenchOptions o;
  RecordedSet set;
  BenchSystems sys;
  ObjectRecognizer& recognizer() const { return *sys.facade.recognizer; }
  const PipelineResult& stereo() const { return recognizer().stereo_result(); }
};

// The scene's truth and the images the system reads, degraded as asked.
Status LoadScene(const RecordedBench& b, const std::string& name, bool monocular, SceneTruth* truth,
                 LoadedImage* left, LoadedImage* right) {
  const std::string base = SceneFolderPath(b.o.dir, name);
  SH_RETURN_IF_ERROR(ParseTruth(base + "truth.json", b.set.tables.models(), truth));
  const ImageDegradation& degradation = b.o.degradation;
  if (!monocular || b.sys.camera == 0) {
    SH_RETURN_IF_ERROR(LoadImage((base + "left.png").c_str(), "left", left));
    SH_RETURN_IF_ERROR(DegradeLoaded(degradation, DegradationSeed(name.c_str(), 0), left));
  }
  if (!monocular || b.sys.camera == 1) {
    SH_RETURN_IF_ERROR(LoadImage((base + "right.png").c_str(), "right", right));
    SH_RETURN_IF_ERROR(DegradeLoaded(degradation, DegradationSeed(name.c_str(), 1), right));
  }
  return Status::Ok();
}

// The scene through the facade: the stereo pair, or the monocular mode's camera.
Status RecognizeScene(RecordedBench& b, bool monocular, const LoadedImage& left,
                      const LoadedImage& right) {
  RecognitionOutput* out = b.sys.facade.output.get();
  if (monocular) {
    const ConstGrayView image = b.sys.camera == 0 ? left.view : right.view;
    return b.recognizer().ProcessMonocular(b.sys.camera, image, b.o.options.budget_ms, out);
  }
  b.sys.trace.Clear();
  const StereoInput pair{left.frame, right.frame, left.view, right.view};
  return b.recognizer().Process(pair, b.o.options.budget_ms, out);
}

// The objects the system reported in the scene, as its recogniser gave them.
const Vector<RecognizedObject>& Reported(const RecordedBench& b, bool monocular) {
  return monocular
             ? static_cast<const Vector<RecognizedObject>&>(b.recognizer().mono_result()->objects)
             : static_cast<const Vector<RecognizedObject>&>(b.stereo().objects);
}

std::vector<RecognizedPose> PosesOf(const Vector<RecognizedObject>& objects) {
  std::vector<RecognizedPose> poses;
  for (const RecognizedObject& o : objects) poses.push_back({o.model, o.cam_T_model});
  return poses;
}

// The row of the scene's background and occlusion, added when it is the first such scene.
ScoreRow& RowOf(const SceneTruth& truth, std::vector<ScoreRow>* rows) {
  auto it = std::find_if(rows->begin(), rows->end(), [&](const ScoreRow& r) {
    return r.background == truth.background && r.occlusion == truth.occlusion;
  });
  if (it != rows->end()) return *it;
  rows->push_back(ScoreRow{});
  rows->back().background = truth.background;
  rows->back().occlusion = truth.occlusion;
  return rows->back();
}

// The errors of the poses before the final edge fit, for its effect on the errors.
void AddFeatureErrors(const RecordedBench& b, const SceneTruth& truth, ScoreRow* row) {
  std::vector<RecognizedPose> feature_poses;
  for (const RecognizedObject& o : b.stereo().objects) {
    feature_poses.push_back({o.model, o.cam_T_model_features});
  }
  const MatchCounts mf =
      MatchToTruth(b.set.models, truth.objects, feature_poses, b.o.max_t_mm, b.o.max_r_deg);
  row->feature_t_err_mm.insert(row->feature_t_err_mm.end(), mf.translation_errors_mm.begin(),
                               mf.translation_errors_mm.end());
  row->feature_r_err_deg.insert(row->feature_r_err_deg.end(), mf.rotation_errors_deg.begin(),
                                mf.rotation_errors_deg.end());
}

// The carried plane's state after the scene (--carry-table) as JSON members.
std::string CarryJson(const RecordedBench& b, const std::string& name, Summary* sum) {
  const PipelineResult& result = b.stereo();
  const TableCarry& carry = result.table_carry;
  if (result.table_source == TableSource::kCarried) ++sum->carried;
  sum->drops = static_cast<int>(carry.drops());
  char buffer[200];
  std::snprintf(buffer, sizeof(buffer),
                "\"table_carry\": {\"state\": \"%s\", \"agreeing\": %u, \"misfits\": %u, "
                "\"resting\": %u, \"drops\": %u}, ",
                TableCarryStateName(carry.state()), carry.agreeing(), carry.misfits(),
                result.table_resting, carry.drops());
  if (b.o.verbose) {
    std::printf("%s: table %s; carry %s, %u agreeing, %u misfits, %u of %zu resting\n",
                name.c_str(), TableSourceName(result.table_source),
                TableCarryStateName(carry.state()), carry.agreeing(), carry.misfits(),
                result.table_resting, result.objects.size());
  }
  return buffer;
}

// The scene's table estimate, scored against DIR/table.yaml when the set has one, as JSON
// members.
std::string EstimateJson(const RecordedBench& b, const std::string& name, Summary* sum) {
  const PipelineResult& result = b.stereo();
  const TableEstimate& e = result.table_estimate;
  ++sum->estimates;
  sum->table_ms.push_back(result.time.table_ms);
  float normal_err = -1, offset_err = 0;
  const bool scored = b.set.have_reference;
  if (scored) {
    // Angle between the normals; height of the reference origin over the estimated plane.
    const RigidTransform& reference = b.set.reference;
    const Eigen::Vector3f n = e.left_T_table.R.col(2);
    normal_err = std::acos(std::min(1.0f, n.dot(reference.R.col(2)))) * 57.29578f;
    offset_err = n.dot(reference.t_mm - e.left_T_table.t_mm);
  }
  if (e.accepted()) {
    ++sum->estimates_accepted;
    if (scored) {
      sum->normal_err_deg.push_back(normal_err);
      sum->offset_err_mm.push_back(std::fabs(offset_err));
    }
  }
  if (b.o.verbose) {
    std::printf(
        "%s: table estimate %s: %u of %u objects rest on it, rms %.2f mm, %u features "
        "dropped",
        name.c_str(), TableEstimateOutcomeName(e.outcome), e.resting, e.objects, e.rms_mm,
        result.table_dropped);
    if (scored && e.accepted()) {
      std::printf("; against table.yaml %.2f deg, %.2f mm", normal_err, offset_err);
    }
    std::printf("\n");
  }
  char buffer[320];
  std::snprintf(buffer, sizeof(buffer),
                "\"table_estimate\": {\"outcome\": \"%s\", \"objects\": %u, \"resting\": %u, "
                "\"rms_mm\": %.3f, \"dropped\": %u, \"normal_err_deg\": %.3f, "
                "\"offset_mm\": %.2f}, ",
                TableEstimateOutcomeName(e.outcome), e.objects, e.resting, e.rms_mm,
                result.table_dropped, normal_err, offset_err);
  return buffer;
}

// The table the stereo scene used, its carrying and its estimate, as JSON members.
std::string TableJson(const RecordedBench& b, const std::string& name, Summary* sum) {
  const PipelineResult& result = b.stereo();
  std::string json = std::string("\"table\": \"") + TableSourceName(result.table_source) + "\", ";
  if (b.sys.config.table_carry.enabled) json += CarryJson(b, name, sum);
  if (result.table_estimate.outcome != TableEstimateOutcome::kDisabled) {
    json += EstimateJson(b, name, sum);
  }
  return json;
}

void CountVisibility(const SceneTruth& truth, const MatchCounts& m, Summary* sum) {
  for (size_t i = 0; i < truth.objects.size(); ++i) {
    const int bin = VisibilityBin(truth.visible[i]);
    ++sum->vis_objects[bin];
    sum->vis_correct[bin] += m.truth_found[i] ? 1 : 0;
  }
}

// --verbose: the scene's counts, and the stereo frame's rescue and colour parts' figures.
void PrintSceneLines(const RecordedBench& b, const std::string& name, const SceneTruth& truth,
                     const MatchCounts& m, float total_ms, bool monocular) {
  std::printf("%s: %d of %zu correct, %d false, %.1f ms\n", name.c_str(), m.correct,
              truth.objects.size(), m.false_alarms, total_ms);
  if (monocular) return;
  const PipelineResult& result = b.stereo();
  if (result.rescue.ran) {
    const RescueStats& rs = result.rescue;
    std::printf(
        "  rescue: %u / %u free corners, %u / %u bases tried (left / right image), found "
        "%u (%u moved by the edge fit), refused %u resting, %u verify, %u overlap; added %u "
        "(%.1f ms)\n",
        rs.free_corners, rs.free_corners_right, rs.search.scene_bases_tried,
        rs.search_right.scene_bases_tried, rs.found, rs.edge_fitted, rs.refused_rest,
        rs.refused_verify, rs.refused_overlap, rs.added, result.time.rescue_ms);
  }
  if (b.set.tables.models().shape_count() > 0) {
    const ShapeStats& sh = result.shape;
    std::printf(
        "  shape path: regions %u / %u, blobs %u / %u, pairs %u, mono %u, hypotheses %u, "
        "verified %u; segment %.1f, search %.1f, refine %.1f, verify %.1f ms\n",
        sh.regions[0], sh.regions[1], sh.blobs[0], sh.blobs[1], sh.pairs, sh.mono_seeds,
        sh.hypotheses, sh.verified, sh.time.segment_ms, sh.time.search_ms, sh.time.refine_ms,
        sh.time.verify_ms);
  }
}

// One reported object as a JSON object: its model, position, vote, verification scores, the
// 3-D features its refinement matched and their fit.
std::string ReportedObjectJson(const std::vector<Model>& models, const RecognizedObject& o) {
  char model_name[kJsonNameBytes];
  char buffer[320 + kJsonNameBytes];
  std::snprintf(
      buffer, sizeof(buffer),
      "{\"model\": \"%s\", \"t\": [%.2f, %.2f, %.2f], \"vote\": %.3f, "
      "\"verify\": [%.3f, %.3f], \"matched\": [%d, %d], \"fit_rms_mm\": %.3f}",
      JsonEscaped(models[o.model].name, sizeof(Model::name), model_name, sizeof(model_name)),
      o.cam_T_model.t_mm.x(), o.cam_T_model.t_mm.y(), o.cam_T_model.t_mm.z(), o.vote,
      o.verify_score[0], o.verify_score[1], o.matched_points, o.matched_lines, o.fit_rms_mm);
  return buffer;
}

// The reported objects as JSON lists: those matching a truth object and the false alarms (also
// as lines, --verbose).
struct ReportedLists {
  std::string found;
  std::string false_alarms;
};

ReportedLists ReportedJson(const RecordedBench& b, const std::string& name, const SceneTruth& truth,
                           const Vector<RecognizedObject>& objects) {
  const std::vector<Model>& models = b.set.models;
  ReportedLists lists;
  for (const RecognizedObject& o : objects) {
    const std::vector<RecognizedPose> one = {{o.model, o.cam_T_model}};
    const bool correct =
        MatchToTruth(models, truth.objects, one, b.o.max_t_mm, b.o.max_r_deg).correct == 1;
    if (!correct && b.o.verbose) {
      std::printf("  %s: false %s at (%.1f, %.1f, %.1f) mm (vote %.2f, verify %.2f %.2f)\n",
                  name.c_str(), models[o.model].name, o.cam_T_model.t_mm.x(),
                  o.cam_T_model.t_mm.y(), o.cam_T_model.t_mm.z(), o.vote, o.verify_score[0],
                  o.verify_score[1]);
    }
    std::string& list = correct ? lists.found : lists.false_alarms;
    list += (list.empty() ? "" : ", ") + ReportedObjectJson(models, o);
  }
  return lists;
}

// One missed object of a stereo frame and what was found at its true pose, as JSON.
std::string MissJson(const RecordedBench& b, const SceneTruth& truth, const MissRecord& miss) {
  const Model& model = b.set.models[truth.objects[miss.truth_index].model];
  char model_name[kJsonNameBytes];
  char lost_to[kJsonNameBytes];
  char buffer[1024 + 2 * kJsonNameBytes];
  std::snprintf(buffer, sizeof(buffer),
                "{\"model\": \"%s\", \"visible\": %.3f, \"cause\": \"%s\", "
                "\"verify_at_truth\": [%.3f, %.3f], \"support_at_truth\": %.3f, "
                "\"own_bases\": %d, \"first_own_rank\": %d, \"good_bases\": %d, "
                "\"first_good_rank\": %d, \"candidates\": %d, \"near_hypotheses\": %d, "
                "\"refined_close\": %d, \"too_close\": %d, \"rejected\": %d, "
                "\"verified\": %d, \"lost_to\": \"%s\", \"edges\": [%d, %d, %d, %d], "
                "\"corners\": [%d, %d, %d, %d], \"edges_2d_both\": %d, "
                "\"edges_lost_stereo\": %d, \"edges_lost_epipolar\": %d}",
                JsonEscaped(model.name, sizeof(model.name), model_name, sizeof(model_name)),
                truth.visible[miss.truth_index], miss.cause, miss.verify_score[0],
                miss.verify_score[1], miss.support, miss.own_bases, miss.first_own_rank,
                miss.good_bases, miss.first_good_rank, miss.candidates, miss.near_hypotheses,
                miss.refined_close, miss.too_close, miss.rejected, miss.verified,
                JsonEscaped(miss.lost_to, sizeof(Model::name), lost_to, sizeof(lost_to)),
                miss.edges_visible, miss.edges_2d[0], miss.edges_2d[1], miss.edges_3d,
                miss.corners_visible, miss.corners_2d[0], miss.corners_2d[1], miss.corners_3d,
                miss.edges_2d_both, miss.edges_lost_stereo, miss.edges_lost_epipolar);
  return buffer;
}

// One missed object of a monocular frame and what its diagnosis found at its true pose, as JSON:
// the image's corners and edge pieces there (detected, shown), the share of its edge samples
// confirmed, and the scene bases on it (all, those voting its model, those finding it).
std::string MonoMissJson(const RecordedBench& b, const SceneTruth& truth, const MonoMiss& miss) {
  const Model& model = b.set.models[truth.objects[miss.truth_index].model];
  const MonoDiagnosis& d = miss.diagnosis;
  char model_name[kJsonNameBytes];
  char buffer[512 + kJsonNameBytes];
  std::snprintf(buffer, sizeof(buffer),
                "{\"model\": \"%s\", \"visible\": %.3f, \"cause\": \"%s\", "
                "\"corners\": [%d, %d], \"edge_pieces\": [%d, %d], "
                "\"verify_at_truth\": %.3f, \"own_bases\": %d, \"good_bases\": %d, "
                "\"finding_bases\": %d, \"first_finding_rank\": %d}",
                JsonEscaped(model.name, sizeof(model.name), model_name, sizeof(model_name)),
                truth.visible[miss.truth_index], MonoMissCauseKey(miss.cause), d.corners_detected,
                d.corners_visible, d.pieces_detected, d.pieces_visible, d.verify_fraction,
                d.object_bases, d.bases_with_model, d.bases_found, d.best_rank);
  return buffer;
}

// Why the scene's objects were missed, judged at their true poses: counted into the summary,
// and as JSON objects.
std::string ExplainSceneMisses(RecordedBench& b, const std::string& name, const SceneTruth& truth,
                               bool monocular, Summary* sum) {
  if (monocular) {
    MonoPipeline& mono = *b.recognizer().mono_pipeline();
    std::vector<MonoMiss> misses;
    ExplainMonoMisses(b.set.models, truth.objects, b.recognizer().mono_result()->objects,
                      mono.features(), mono.recognizer(), name.c_str(), b.o.verbose,
                      sum->misses.mono, b.o.max_t_mm, b.o.max_r_deg, &misses);
    std::string json;
    for (const MonoMiss& miss : misses)
      json += (json.empty() ? "" : ", ") + MonoMissJson(b, truth, miss);
    return json;
  }
  std::vector<MissRecord> misses;
  ExplainMisses(b.set.models, truth.objects, b.stereo(), b.recognizer().pipeline(), name.c_str(),
                b.o.verbose, &sum->misses.stereo, b.o.max_t_mm, b.o.max_r_deg, &misses,
                b.sys.search.get(), &b.sys.trace);
  std::string json;
  for (const MissRecord& miss : misses)
    json += (json.empty() ? "" : ", ") + MissJson(b, truth, miss);
  return json;
}

// The stereo frame's feature counts, search and rescue as JSON members.
std::string StereoSceneJson(const PipelineResult& result) {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer),
                "\"points3d\": %u, \"lines3d\": %u, \"scene_bases_tried\": %u, "
                "\"held_back\": %u, \"held_back_accepted\": %u, \"second_looks\": %u, "
                "\"rescue\": {\"ran\": %s, \"ran_right\": %s, \"found\": %u, "
                "\"added\": %u, \"ms\": %.2f}, ",
                result.points3d, result.lines3d, result.recognition.scene_bases_tried,
                result.recognition.deferred, result.recognition.deferred_accepted,
                result.second_looks, result.rescue.ran ? "true" : "false",
                result.rescue.ran_right ? "true" : "false", result.rescue.found,
                result.rescue.added, result.time.rescue_ms);
  return buffer;
}

// Scores one recognised scene: its row, the summary's tallies, the scene's JSON.
void ScoreScene(RecordedBench& b, const std::string& name, const SceneTruth& truth, bool monocular,
                std::vector<ScoreRow>* rows, Summary* sum) {
  const Vector<RecognizedObject>& objects = Reported(b, monocular);
  const MatchCounts m =
      MatchToTruth(b.set.models, truth.objects, PosesOf(objects), b.o.max_t_mm, b.o.max_r_deg);
  ScoreRow& row = RowOf(truth, rows);
  row.AddMatch(m, truth.objects.size());
  std::string table_json;
  if (monocular) {
    row.AddMonoFrame(*b.recognizer().mono_result());
  } else {
    AddFeatureErrors(b, truth, &row);
    row.AddStereoFrame(b.stereo());
    table_json = TableJson(b, name, sum);
  }
  const float total_ms = row.time_ms.back();
  CountVisibility(truth, m, sum);
  if (!monocular) sum->rescue.Add(b.stereo());
  if (b.o.verbose) PrintSceneLines(b, name, truth, m, total_ms, monocular);
  const ReportedLists reported = ReportedJson(b, name, truth, objects);
  const std::string missed_json = ExplainSceneMisses(b, name, truth, monocular, sum);
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer),
                "%s\n    {\"scene\": \"%s\", \"background\": \"%s\", \"occlusion\": \"%s\", "
                "\"objects\": %zu, \"correct\": %d, \"false_alarms\": %d, \"total_ms\": %.2f, ",
                sum->scene_json.empty() ? "" : ",", name.c_str(), truth.background.c_str(),
                truth.occlusion.c_str(), truth.objects.size(), m.correct, m.false_alarms, total_ms);
  sum->scene_json += buffer;
  if (!monocular) sum->scene_json += StereoSceneJson(b.stereo());
  sum->scene_json += table_json;
  sum->scene_json.append("\"missed\": [").append(missed_json);
  sum->scene_json.append("], \"found\": [").append(reported.found);
  sum->scene_json.append("], \"false\": [").append(reported.false_alarms).append("]}");
}

// The heading of a system's table: the set, the scoring and the table in use.
void PrintHeading(const RecordedBench& b, bool monocular) {
  const TableChoice& table = b.set.table;
  const char* table_name = table.present ? table.source.c_str() : "none";
  if (monocular) {
    std::printf(
        "\nRecorded scenes %s, monocular (%s images): %zu scenes; correct = same model, "
        "within %.0f mm and %.0f deg (symmetry-aware);\n2-D counts per image, counts and "
        "times medians over the row; pose errors medians over the correct objects; table: "
        "%s.\n\n",
        b.o.dir.c_str(), b.sys.camera == 0 ? "left" : "right", b.set.scenes.size(), b.o.max_t_mm,
        b.o.max_r_deg, table_name);
    return;
  }
  const int threads = b.recognizer().pipeline().threads();
  std::printf(
      "\nRecorded scenes %s: %zu scenes; correct = same model, within %.0f mm and %.0f deg "
      "(symmetry-aware);\n2-D counts per image (mean of left and right), counts and times "
      "medians over the row; pose errors\nmedians over the correct objects; table: %s; %d "
      "thread%s.\n\n",
      b.o.dir.c_str(), b.set.scenes.size(), b.o.max_t_mm, b.o.max_r_deg, table_name, threads,
      threads == 1 ? "" : "s");
}

// The rows and their total, printed and as JSON.
void PrintRows(const std::vector<ScoreRow>& rows, Summary* sum) {
  PrintScoreHeader();
  sum->total = ScoreRow{};
  sum->total.background = "all";
  for (const ScoreRow& row : rows) {
    PrintScoreRow(row);
    sum->total.Add(row);
    sum->rows_json += (sum->rows_json.empty() ? "\n    " : ",\n    ") + ScoreRowJson(row, false);
  }
  PrintScoreRow(sum->total);
}

// Recall, false alarms, pose errors and stage times over every scene.
void PrintTotals(const Summary& sum, bool monocular) {
  const ScoreRow& total = sum.total;
  const double correct_pct = Percent(total.correct, total.objects);
  const double false_pct = Percent(total.false_alarms, total.correct + total.false_alarms);
  if (monocular) {
    std::printf(
        "\ncorrect %.1f %% of objects, false alarms %.1f %% of reported objects; median error "
        "%.2f mm / %.2f deg;\nframe median %.1f ms, worst %.1f ms; median stage times: "
        "features %.1f, recognition %.1f ms\n",
        correct_pct, false_pct, Median(total.t_err_mm), Median(total.r_err_deg),
        Median(total.time_ms), Max(total.time_ms), Median(total.features_ms),
        Median(total.hashing_ms));
    return;
  }
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

// The table estimates against DIR/table.yaml, and the carried plane (--carry-table).
void PrintTableFigures(const RecordedBench& b, const Summary& sum, bool monocular) {
  if (sum.estimates > 0) {
    std::printf("table estimated in %d of %d scenes, %.2f ms median, %.2f ms worst",
                sum.estimates_accepted, sum.estimates, Median(sum.table_ms), Max(sum.table_ms));
    if (!sum.normal_err_deg.empty()) {
      std::printf(
          "; against table.yaml: normal %.2f deg median, %.2f worst; offset %.2f mm "
          "median, %.2f worst",
          Median(sum.normal_err_deg), Max(sum.normal_err_deg), Median(sum.offset_err_mm),
          Max(sum.offset_err_mm));
    }
    std::printf("\n");
  }
  if (b.sys.config.table_carry.enabled && !monocular) {
    std::printf("table carried in %d of %zu scenes, dropped %d times\n", sum.carried,
                b.set.scenes.size(), sum.drops);
  }
}

// Recall per visibility bin, printed (no newline) and as JSON.
void PrintVisibility(Summary* sum) {
  std::printf("recall by visibility:");
  for (int b = 0; b < kVisibilityBins; ++b) {
    std::printf("%s %s %d / %d (%.1f %%)", b ? "," : "", kVisibilityNames[b], sum->vis_correct[b],
                sum->vis_objects[b], Percent(sum->vis_correct[b], sum->vis_objects[b]));
    char buffer[160];
    std::snprintf(buffer, sizeof(buffer),
                  "%s{\"visible\": \"%s\", \"objects\": %d, \"correct\": %d}", b ? ", " : "",
                  kVisibilityNames[b], sum->vis_objects[b], sum->vis_correct[b]);
    sum->vis_json += buffer;
  }
}

// One system over every scene: prints its table and fills its summary.
Status RunSystem(RecordedBench& b, bool monocular, Summary* sum) {
  std::vector<ScoreRow> rows;
  LoadedImage left, right;
  for (const std::string& name : b.set.scenes) {
    SceneTruth truth;
    Status st = LoadScene(b, name, monocular, &truth, &left, &right);
    if (st.ok()) st = RecognizeScene(b, monocular, left, right);
    if (!st.ok()) return Status::Error(st.code(), "%s: %s", name.c_str(), st.message());
    ScoreScene(b, name, truth, monocular, &rows, sum);
  }
  PrintHeading(b, monocular);
  PrintRows(rows, sum);
  PrintTotals(*sum, monocular);
  if (!monocular && b.recognizer().rescue_lent()) sum->rescue.Print(b.set.scenes.size());
  PrintTableFigures(b, *sum, monocular);
  PrintVisibility(sum);
  std::printf("\n");
  sum->misses.Print(monocular, sum->total);
  return Status::Ok();
}

// The recall table of a run over several noise levels: what a camera's gain costs.
void PrintRecallAgainstNoise(const std::vector<float>& levels, const std::vector<Summary>& sums,
                             const ImageDegradation& degradation) {
  std::printf("\nrecall against noise (blur %.1f px, gain %.2f; correct and false as above):\n",
              degradation.blur_sigma_px, degradation.gain);
  std::printf("%8s %9s %9s %9s %9s %8s %8s %8s %9s\n", "noise", "correct", ">= 70 %", "40-70 %",
              "false", "t mm", "R deg", "med ms", "worst ms");
  for (size_t i = 0; i < levels.size(); ++i) {
    const Summary& sum = sums[i];
    const ScoreRow& t = sum.total;
    std::printf("%8.1f %8.1f%% %8.1f%% %8.1f%% %8.1f%% %8.3f %8.3f %8.1f %9.1f\n", levels[i],
                Percent(t.correct, t.objects), Percent(sum.vis_correct[2], sum.vis_objects[2]),
                Percent(sum.vis_correct[1], sum.vis_objects[1]),
                Percent(t.false_alarms, t.correct + t.false_alarms), Median(t.t_err_mm),
                Median(t.r_err_deg), Median(t.time_ms), Max(t.time_ms));
  }
}

// One level of that table for the JSON: {"noise_sigma", "objects", "correct", ...}.
std::string NoiseLevelJson(float level, const Summary& sum) {
  const ScoreRow& t = sum.total;
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

// Thesis 6.4.3: the 2-D system beside the 3-D one on the same scenes.
void PrintSideBySide(const Summary& stereo, const Summary& mono) {
  std::printf("\nside by side (thesis ch. 6): %-8s %8s %8s %8s %10s %10s %10s\n", "", "correct",
              "false", "missed", "t err mm", "R err deg", "median ms");
  for (const auto& [label, sum] :
       {std::pair<const char*, const Summary*>{"stereo", &stereo}, {"mono", &mono}}) {
    const ScoreRow& t = sum->total;
    std::printf("                             %-8s %7.1f%% %7.1f%% %8d %10.2f %10.2f %10.1f\n",
                label, Percent(t.correct, t.objects),
                Percent(t.false_alarms, t.correct + t.false_alarms), t.missed, Median(t.t_err_mm),
                Median(t.r_err_deg), Median(t.time_ms));
  }
}

// The figures of every run: the first noise level's in full, each level's totals.
struct Runs {
  Summary stereo, mono;
  std::vector<Summary> levels;
};

// One run of each system per noise level; the first level's figures are the ones reported in
// full.
Status RunLevels(RecordedBench& b, Runs* runs) {
  const std::vector<float>& noise_levels = b.o.noise_levels;
  runs->levels.resize(noise_levels.size());
  for (size_t level = 0; level < noise_levels.size(); ++level) {
    ImageDegradation& degradation = b.o.degradation;
    degradation.noise_sigma = noise_levels[level];
    if (!degradation.none()) {
      std::printf("\n==== images degraded: noise sigma %.1f grey levels, blur %.1f px, gain %.2f\n",
                  degradation.noise_sigma, degradation.blur_sigma_px, degradation.gain);
    }
    if (b.sys.run_stereo) {
      SH_RETURN_IF_ERROR(RunSystem(b, false, level == 0 ? &runs->stereo : &runs->levels[level]));
    }
    if (b.sys.run_mono) {
      SH_RETURN_IF_ERROR(RunSystem(b, true, level == 0 ? &runs->mono : &runs->levels[level]));
    }
  }
  runs->levels[0] = b.sys.run_mono ? runs->mono : runs->stereo;
  return Status::Ok();
}

// One system's figures for the JSON: "summary", "visibility", "rows", "scenes".
std::string SystemJson(const Summary& sum, bool monocular, size_t scenes) {
  const ScoreRow& total = sum.total;
  char summary[768];
  std::snprintf(summary, sizeof(summary),
                "\"summary\": {\"scenes\": %zu, \"objects\": %d, \"correct\": %d, \"missed\": %d, "
                "\"false_alarms\": %d, \"correct_pct\": %.2f, \"false_alarm_pct\": %.2f, "
                "\"median_t_err_mm\": %.3f, \"median_r_err_deg\": %.3f, "
                "\"feature_median_t_err_mm\": %.3f, \"feature_median_r_err_deg\": %.3f, "
                "\"median_ms\": %.2f, \"worst_ms\": %.2f, \"miss_causes\": %s}",
                scenes, total.objects, total.correct, total.missed, total.false_alarms,
                Percent(total.correct, total.objects),
                Percent(total.false_alarms, total.correct + total.false_alarms),
                Median(total.t_err_mm), Median(total.r_err_deg), Median(total.feature_t_err_mm),
                Median(total.feature_r_err_deg), Median(total.time_ms), Max(total.time_ms),
                sum.misses.Json(monocular).c_str());
  std::string json = std::string("  ") + summary + ",\n";
  json += "  \"visibility\": [" + sum.vis_json + "],\n";
  json += "  \"rows\": [" + sum.rows_json + "\n  ],\n";
  json += "  \"scenes\": [" + sum.scene_json + "\n  ]";
  return json;
}

// The degradation and the recall per noise level, when the images were degraded.
std::string DegradationJson(const RecordedBench& b, const Runs& runs) {
  const ImageDegradation& degradation = b.o.degradation;
  const std::vector<float>& noise_levels = b.o.noise_levels;
  if (degradation.none() && noise_levels.size() <= 1) return "";
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer),
                "  \"degradation\": {\"blur_sigma_px\": %.2f, \"gain\": %.3f},\n",
                degradation.blur_sigma_px, degradation.gain);
  std::string json = buffer;
  json += "  \"noise_levels\": [";
  for (size_t i = 0; i < noise_levels.size(); ++i) {
    json += (i ? ",\n    " : "\n    ") + NoiseLevelJson(noise_levels[i], runs.levels[i]);
  }
  json += "\n  ],\n";
  return json;
}

std::string BenchJson(const RecordedBench& b, const Runs& runs, int argc, char** argv) {
  std::string json = "{\n  \"command\": \"" + CommandLine(argc, argv) + "\",\n";
  json += DegradationJson(b, runs);
  const TableChoice& table = b.set.table;
  json += "  \"table\": \"" + (table.present ? table.source : std::string("none")) + "\",\n";
  const size_t scenes = b.set.scenes.size();
  if (b.o.compare) {
    json += "  \"stereo\": {\n" + SystemJson(runs.stereo, false, scenes) + "\n  },\n";
    json += "  \"monocular\": {\n" + SystemJson(runs.mono, true, scenes) + "\n  }\n}\n";
  } else {
    const bool mono = b.sys.run_mono;
    if (mono) json += "  \"mode\": \"monocular\",\n";
    json += SystemJson(mono ? runs.mono : runs.stereo, mono, scenes) + "\n}\n";
  }
  return json;
}

int Fail(const char* message) {
  std::fprintf(stderr, "stereohash bench recorded: %s\n", message);
  return 1;
}

// The set loaded and the systems set up; -1 to go on, else the exit code.
int Prepare(RecordedBench* b) {
  Status s = LoadSet(b->o, &b->set);
  if (!s.ok()) return Fail(s.message());
  if (!ModesAgree(b->o, b->set)) return 2;
  if (!TuneConfigs(b->o, b->set, &b->sys)) return 2;
  s = SetUpSystems(b->o, b->set, &b->sys);
  if (!s.ok()) return Fail(s.message());
  return -1;
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
  auto bench = std::make_unique<RecordedBench>();
  bench->o.dir = argv[2];
  int exit_code = ParseOptions(argc, argv, &bench->o);
  if (exit_code >= 0) return exit_code;
  std::printf("command: %s\n", CommandLine(argc, argv).c_str());
  exit_code = Prepare(bench.get());
  if (exit_code >= 0) return exit_code;
  auto runs = std::make_unique<Runs>();
  const Status s = RunLevels(*bench, runs.get());
  if (!s.ok()) return Fail(s.message());
  if (bench->o.noise_levels.size() > 1) {
    PrintRecallAgainstNoise(bench->o.noise_levels, runs->levels, bench->o.degradation);
  }
  if (bench->o.compare) PrintSideBySide(runs->stereo, runs->mono);
  const char* json_path = bench->o.json_path;
  if (json_path != nullptr && !WriteTextFile(json_path, BenchJson(*bench, *runs, argc, argv))) {
    std::fprintf(stderr, "stereohash bench recorded: cannot write %s\n", json_path);
    return 1;
  }
  return 0;
}

}  // namespace sh::tools
