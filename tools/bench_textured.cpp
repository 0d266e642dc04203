// `stereohash bench textured`: the texture path on printed cartons, beside a peer made of
// OpenCV's parts, on a recorded set (DIR/calib.yaml, DIR/sceneNN/{left,right}.png, truth.json)
// or on scenes of our own renderer (held-out seeds), scored as the recorded sets' README says:
// same model, within 5 mm and 5 degrees (no symmetries: the print breaks them).
#include "tools/bench_textured.hpp"

#include <dirent.h>
#include <errno.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "hal/sim/textured_model_files.hpp"
#include "hal/sim/world/printed_surface.hpp"
#include "hal/sim/world/renderer.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/texture/texture_recognizer.hpp"
#include "tables/feature_db_view.hpp"
#include "tools/command.hpp"
#include "tools/eval/mini_json.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/eval/synthetic_scene.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"
#include "tools/tablegen/feature_db_builder.hpp"
#ifdef STEREOHASH_OPENCV_PEER
#include "tools/opencv_texture_peer.hpp"
#endif

namespace sh::tools {
namespace {

constexpr float kMaxPositionErrorMm = 5.0f;
constexpr float kMaxRotationErrorDeg = 5.0f;
constexpr const char* kCartons[] = {"tea", "cereal", "pills", "tools"};

void PrintHelp() {
  std::printf(
      "usage: stereohash bench textured (--recorded DIR | --rendered N) [--seed S]\n"
      "                                 [--models DIR] [--no-peer] [--json OUT] [--verbose]\n"
      "                                 [--save DIR] [--camera wide|tele|hd]\n"
      "Runs the texture path (and a peer of OpenCV SIFT + FLANN + RANSAC homography + solvePnP\n"
      "+ stereo, unless --no-peer) on printed cartons and scores both: correct = same model\n"
      "within 5 mm and 5 deg. The feature database is learnt from the models first.\n"
      "  --recorded DIR  a recorded set (DIR/calib.yaml, DIR/sceneNN/left.png, right.png,\n"
      "                  truth.json; a scene's own calib.yaml takes precedence)\n"
      "  --rendered N    N scenes per background x occlusion row from our renderer, seeds from\n"
      "                  S (default 1000, never used for tuning)\n"
      "  --models DIR    the printed models (default models/textured): tea, cereal, pills, tools\n"
      "  --save DIR      with --rendered: also write the scenes as a recorded set to DIR\n"
      "  --camera NAME   with --rendered: another camera than the thesis's "
      "(scene_generator.hpp)\n");
}

struct Scene {
  std::string name, background, occlusion;
  std::vector<TruthObject> truth;
  std::vector<float> visible;  // mean of left and right
  std::vector<uint8_t> left, right;
  int width = 0, height = 0;
  StereoCalibration calib;  // the rendered rigs differ from scene to scene
};

struct Score {
  int objects = 0, correct = 0, missed = 0, false_alarms = 0, reported = 0;
  int vis_total[3] = {0, 0, 0}, vis_found[3] = {0, 0, 0};
  std::vector<float> t_err, r_err, total_ms;
  std::vector<float> stage_ms[4];  // features, matching, clustering, stereo (+ verification)
};

int VisibilityBin(float v) { return v < 0.4f ? 0 : v < 0.7f ? 1 : 2; }

void ScoreScene(const std::vector<Model>& models, const Scene& s,
                const std::vector<RecognizedPose>& found, Score* score, bool verbose,
                const char* who) {
  const MatchCounts c =
      MatchToTruth(models, s.truth, found, kMaxPositionErrorMm, kMaxRotationErrorDeg);
  score->objects += static_cast<int>(s.truth.size());
  score->correct += c.correct;
  score->missed += c.missed;
  score->false_alarms += c.false_alarms;
  score->reported += static_cast<int>(found.size());
  score->t_err.insert(score->t_err.end(), c.translation_errors_mm.begin(),
                      c.translation_errors_mm.end());
  score->r_err.insert(score->r_err.end(), c.rotation_errors_deg.begin(),
                      c.rotation_errors_deg.end());
  for (size_t i = 0; i < s.truth.size(); ++i) {
    const int bin = VisibilityBin(s.visible[i]);
    ++score->vis_total[bin];
    score->vis_found[bin] += c.truth_found[i] ? 1 : 0;
    if (verbose && !c.truth_found[i]) {
      std::printf("  %s %s: missed %s (%.0f %% visible)\n", who, s.name.c_str(),
                  models[static_cast<size_t>(s.truth[i].model)].name, 100.0f * s.visible[i]);
    }
  }
  if (verbose && c.false_alarms > 0) {
    std::printf("  %s %s: %d false alarm(s)\n", who, s.name.c_str(), c.false_alarms);
  }
}

void PrintScore(const char* who, const Score& s) {
  const double pct = s.objects > 0 ? 100.0 * s.correct / s.objects : 0;
  const double fa = s.reported > 0 ? 100.0 * s.false_alarms / s.reported : 0;
  std::printf(
      "%-8s %3d/%3d correct (%5.1f %%), %2d missed, %2d false alarms (%4.1f %% of reported); "
      "recall by visibility <40 %%: %d/%d, 40-70 %%: %d/%d, >=70 %%: %d/%d; median error %.2f mm "
      "%.2f deg; frame median %.1f ms, worst %.1f ms (features %.1f, matching %.1f, clustering "
      "%.1f, stereo + pose %.1f)\n",
      who, s.correct, s.objects, pct, s.missed, s.false_alarms, fa, s.vis_found[0], s.vis_total[0],
      s.vis_found[1], s.vis_total[1], s.vis_found[2], s.vis_total[2], Median(s.t_err),
      Median(s.r_err), Median(s.total_ms), Max(s.total_ms), Median(s.stage_ms[0]),
      Median(s.stage_ms[1]), Median(s.stage_ms[2]), Median(s.stage_ms[3]));
}

std::string ScoreJson(const Score& s) {
  char b[1024];
  std::snprintf(b, sizeof(b),
                "{\"objects\": %d, \"correct\": %d, \"missed\": %d, \"false_alarms\": %d, "
                "\"reported\": %d, \"recall_by_visibility\": [[%d, %d], [%d, %d], [%d, %d]], "
                "\"median_t_err_mm\": %.3f, \"median_r_err_deg\": %.3f, \"median_ms\": %.2f, "
                "\"worst_ms\": %.2f, \"median_stage_ms\": {\"features\": %.2f, \"matching\": "
                "%.2f, \"clustering\": %.2f, \"stereo_pose\": %.2f}}",
                s.objects, s.correct, s.missed, s.false_alarms, s.reported, s.vis_found[0],
                s.vis_total[0], s.vis_found[1], s.vis_total[1], s.vis_found[2], s.vis_total[2],
                Median(s.t_err), Median(s.r_err), Median(s.total_ms), Max(s.total_ms),
                Median(s.stage_ms[0]), Median(s.stage_ms[1]), Median(s.stage_ms[2]),
                Median(s.stage_ms[3]));
  return b;
}

int ModelIndex(const std::vector<Model>& models, const std::string& name) {
  for (size_t i = 0; i < models.size(); ++i) {
    if (name == models[i].name) return static_cast<int>(i);
  }
  return -1;
}

// The scenes of a recorded set, in folder order.
Status LoadRecorded(const std::string& dir, const StereoCalibration& calib,
                    const std::vector<Model>& models, std::vector<Scene>* scenes) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d)) {
      struct stat st {};
      const std::string base = dir + "/" + e->d_name;
      if (e->d_name[0] != '.' && stat((base + "/truth.json").c_str(), &st) == 0) {
        names.push_back(e->d_name);
      }
    }
    closedir(d);
  }
  if (names.empty()) {
    return Status::Error(StatusCode::kNotFound, "%s holds no scene folders (sceneNN/truth.json)",
                         dir.c_str());
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    Scene s;
    s.name = name;
    std::string base = dir;
    base.append("/").append(name).append("/");
    std::string text;
    Json json;
    if (!ReadTextFile(base + "truth.json", &text) || !JsonReader(text).Parse(&json)) {
      return Status::Error(StatusCode::kInvalidArgument, "%s/truth.json: not readable JSON",
                           name.c_str());
    }
    s.background = json["background"].text;
    s.occlusion = json["occlusion"].text;
    for (const Json& o : json["objects"].items) {
      TruthObject t;
      t.model = ModelIndex(models, o["model"].text);
      if (t.model < 0 || o["R"].size() != 3 || o["t"].size() != 3) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s/truth.json: object '%s' is not one of the models or has no pose",
                             name.c_str(), o["model"].text.c_str());
      }
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t.cam_T_model.R(r, c) = static_cast<float>(o["R"][r][c].number);
        t.cam_T_model.t_mm(r) = static_cast<float>(o["t"][r].number);
      }
      s.truth.push_back(t);
      const Json& v = o["visible"];
      s.visible.push_back(v.size() == 2 ? static_cast<float>(0.5 * (v[0].number + v[1].number))
                                        : 1.0f);
    }
    LoadedImage l, r;
    Status st = LoadImage((base + "left.png").c_str(), "left", &l);
    if (st.ok()) st = LoadImage((base + "right.png").c_str(), "right", &r);
    if (!st.ok()) return st;
    s.calib = calib;
    struct stat own {};
    if (stat((base + "calib.yaml").c_str(), &own) == 0) {  // a rig of its own (--save)
      const Result<StereoCalibration> c = LoadFrameCalibration((base + "calib.yaml").c_str());
      if (!c.ok()) return c.status();
      s.calib = *c;
    }
    s.width = l.view.width;
    s.height = l.view.height;
    s.left.assign(l.view.data, l.view.data + size_t{1} * s.width * s.height);
    s.right.assign(r.view.data, r.view.data + size_t{1} * s.width * s.height);
    scenes->push_back(std::move(s));
  }
  return Status::Ok();
}

// Scenes of our renderer: per background x occlusion row, n scenes with seeds from `seed`.
Status RenderScenes(int n, uint64_t seed, const render::ScenarioParams& camera,
                    const std::vector<TexturedModel>& printed, std::vector<Scene>* scenes,
                    StereoCalibration* calib) {
  std::vector<Model> models;
  models.reserve(printed.size());
  for (const TexturedModel& t : printed) models.push_back(t.model);
  std::vector<render::PrintedSurface> prints;
  prints.reserve(printed.size());
  for (const TexturedModel& t : printed) prints.push_back(render::PrintOf(t));
  const struct {
    render::Background bg;
    render::Occlusion occ;
    const char *b, *o;
  } rows[] = {{render::Background::kDark, render::Occlusion::kNone, "dark", "none"},
              {render::Background::kDark, render::Occlusion::kSome, "dark", "some"},
              {render::Background::kDark, render::Occlusion::kSevere, "dark", "severe"},
              {render::Background::kLight, render::Occlusion::kNone, "light", "none"},
              {render::Background::kLight, render::Occlusion::kSome, "light", "some"},
              {render::Background::kLight, render::Occlusion::kSevere, "light", "severe"}};
  for (const auto& row : rows) {
    for (int i = 0; i < n; ++i) {
      render::ScenarioParams p = camera;
      p.background = row.bg;
      p.occlusion = row.occ;
      p.n_objects = 3 + (i % 2);
      p.camera_distance_mm = 400.0f + 10.0f * static_cast<float>((i * 7) % 10);
      p.spread_mm = 300.0f;
      const uint64_t s = seed++;
      Result<render::GeneratedScene> g =
          render::GenerateScene(s, p, models.data(), static_cast<int>(models.size()));
      if (!g.ok()) return g.status();
      for (render::SceneObject& o : g->scene.objects) {
        o.albedo = 0.95f;  // the print sets the reflectance
        o.print = &prints[o.model_index];
      }
      *calib = g->calib;
      Scene sc;
      sc.calib = g->calib;
      char name[32];
      std::snprintf(name, sizeof(name), "seed%llu", static_cast<unsigned long long>(s));
      sc.name = name;
      sc.background = row.b;
      sc.occlusion = row.o;
      sc.width = g->calib.left.width;
      sc.height = g->calib.left.height;
      sc.left.resize(size_t{1} * sc.width * sc.height);
      sc.right.resize(sc.left.size());
      const GrayView left_view{sc.left.data(), sc.width, sc.height, sc.width};
      const GrayView right_view{sc.right.data(), sc.width, sc.height, sc.width};
      SH_RETURN_IF_ERROR(render::RenderStereo(g->scene, models.data(),
                                              static_cast<int>(models.size()), g->calib, left_view,
                                              right_view));
      const std::vector<float> vis_left =
          VisibleFractions(g->scene, models, g->calib.left, g->scene.left_T_table);
      const std::vector<float> vis_right = VisibleFractions(
          g->scene, models, g->calib.right, render::RightFromTable(g->scene, g->calib));
      for (size_t k = 0; k < g->scene.objects.size(); ++k) {
        sc.truth.push_back({g->scene.objects[k].model_index, g->left_T_model[k]});
        sc.visible.push_back(0.5f * (vis_left[k] + vis_right[k]));
      }
      scenes->push_back(std::move(sc));
    }
  }
  return Status::Ok();
}

// Writes the scenes as recorded pairs: DIR/<scene>/{calib.yaml, left.png, right.png,
// truth.json} (poses and visible fractions, as the recorded sets' README describes).
Status SaveScenes(const std::string& dir, const std::vector<Model>& models,
                  const std::vector<Scene>& scenes) {
  if (mkdir(dir.c_str(), 0777) != 0 && errno != EEXIST) {
    return Status::Error(StatusCode::kNotFound, "cannot create %s", dir.c_str());
  }
  for (const Scene& s : scenes) {
    const std::string base = dir + "/" + s.name;
    if (mkdir(base.c_str(), 0777) != 0 && errno != EEXIST) {
      return Status::Error(StatusCode::kNotFound, "cannot create %s", base.c_str());
    }
    // Each rendered scene has its own rig: its calibration goes beside it.
    std::vector<char> yaml(8192);
    const Result<size_t> n = WriteCalibrationYaml(s.calib, yaml.data(), yaml.size());
    if (!n.ok()) return n.status();
    if (!WriteTextFile((base + "/calib.yaml").c_str(), std::string(yaml.data(), *n))) {
      return Status::Error(StatusCode::kNotFound, "cannot write %s/calib.yaml", base.c_str());
    }
    SH_RETURN_IF_ERROR(hal::WritePng((base + "/left.png").c_str(),
                                     ConstGrayView{s.left.data(), s.width, s.height, s.width}));
    SH_RETURN_IF_ERROR(hal::WritePng((base + "/right.png").c_str(),
                                     ConstGrayView{s.right.data(), s.width, s.height, s.width}));
    std::string json = "{\"background\": \"" + s.background + "\", \"occlusion\": \"" +
                       s.occlusion + "\", \"objects\": [";
    for (size_t i = 0; i < s.truth.size(); ++i) {
      const RigidTransform& T = s.truth[i].cam_T_model;
      const Model& model = models[static_cast<size_t>(s.truth[i].model)];
      char name[kJsonNameBytes];
      char b[512 + kJsonNameBytes];
      std::snprintf(b, sizeof(b),
                    "%s{\"model\": \"%s\", \"R\": [[%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f], "
                    "[%.9f, %.9f, %.9f]], \"t\": [%.6f, %.6f, %.6f], \"visible\": [%.3f, %.3f]}",
                    i > 0 ? ", " : "",
                    JsonEscaped(model.name, sizeof(model.name), name, sizeof(name)), T.R(0, 0),
                    T.R(0, 1), T.R(0, 2), T.R(1, 0), T.R(1, 1), T.R(1, 2), T.R(2, 0), T.R(2, 1),
                    T.R(2, 2), T.t_mm.x(), T.t_mm.y(), T.t_mm.z(), s.visible[i], s.visible[i]);
      json += b;
    }
    json += "]}\n";
    if (!WriteTextFile((base + "/truth.json").c_str(), json)) {
      return Status::Error(StatusCode::kNotFound, "cannot write %s/truth.json", base.c_str());
    }
  }
  return Status::Ok();
}

int Fail(const char* message) {
  std::fprintf(stderr, "stereohash bench textured: %s\n", message);
  return 1;
}

struct TexturedOptions {
  const char* recorded = nullptr;
  const char* json_path = nullptr;
  const char* save_dir = nullptr;
  std::string models_dir = "models/textured";
  int rendered = 0;
  uint64_t seed = 1000;
  bool peer = true, verbose = false;
  render::ScenarioParams camera;  // the thesis camera unless --camera
};

// An option with a value; false when the value is missing or bad (said).
bool TakeTexturedValue(const std::string& a, const char* v, TexturedOptions* o) {
  if (a == "--camera") {
    if (v == nullptr || !render::NamedCamera(v, &o->camera)) {
      std::fprintf(stderr, "stereohash bench textured: --camera needs wide, tele or hd\n");
      return false;
    }
    return true;
  }
  if (v == nullptr) {
    std::fprintf(stderr, "stereohash bench textured: %s needs a value\n", a.c_str());
    return false;
  }
  if (a == "--recorded") o->recorded = v;
  if (a == "--rendered") o->rendered = std::atoi(v);
  if (a == "--seed") o->seed = std::strtoull(v, nullptr, 10);
  if (a == "--models") o->models_dir = v;
  if (a == "--json") o->json_path = v;
  if (a == "--save") o->save_dir = v;
  return true;
}

// -1 to go on, else the exit code.
int ParseTexturedOptions(int argc, char** argv, TexturedOptions* o) {
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      PrintHelp();
      return 0;
    } else if (a == "--no-peer") {
      o->peer = false;
    } else if (a == "--verbose") {
      o->verbose = true;
    } else if (a == "--camera" || a == "--recorded" || a == "--rendered" || a == "--seed" ||
               a == "--models" || a == "--json" || a == "--save") {
      const char* v = i + 1 < argc ? argv[++i] : nullptr;
      if (!TakeTexturedValue(a, v, o)) return 2;
    } else {
      std::fprintf(stderr, "stereohash bench textured: unknown option '%s' (see --help)\n",
                   a.c_str());
      return 2;
    }
  }
  if ((o->recorded == nullptr) == (o->rendered <= 0)) {
    std::fprintf(stderr, "stereohash bench textured: give --recorded DIR or --rendered N\n");
    return 2;
  }
  return -1;
}

// The printed models and the feature database learnt from them.
struct PrintedSet {
  std::vector<TexturedModel> printed;
  std::vector<Model> models;
  FeatureDbBuildOptions build;
  std::vector<uint8_t> storage;  // the database, aligned within
  FeatureDbView db;
};

Status LoadPrintedSet(const std::string& models_dir, PrintedSet* set) {
  for (const char* name : kCartons) {
    Result<TexturedModel> m = LoadTexturedModelFile(models_dir + "/" + name + ".obj");
    if (!m.ok()) return m.status();
    set->printed.push_back(std::move(*m));
  }
  set->models.reserve(set->printed.size());
  for (const TexturedModel& t : set->printed) set->models.push_back(t.model);
  FeatureDbBuildReport report;
  Result<std::vector<uint8_t>> blob = BuildFeatureDb(set->printed, set->build, &report);
  if (!blob.ok()) return blob.status();
  set->storage.resize(blob->size() + 64);
  uint8_t* aligned =
      set->storage.data() + (64 - reinterpret_cast<uintptr_t>(set->storage.data()) % 64) % 64;
  std::memcpy(aligned, blob->data(), blob->size());
  Result<FeatureDbView> db = FeatureDbView::Open(aligned, blob->size());
  if (!db.ok()) return db.status();
  set->db = *db;
  std::printf("feature database: %u models, %u faces, %u views, %u features, %zu bytes\n",
              db->model_count(), db->face_count(), db->view_count(), db->feature_count(),
              blob->size());
  return Status::Ok();
}

// The recorded set's scenes, or rendered ones (saved as a recorded set with --save).
Status LoadTexturedScenes(const TexturedOptions& o, const PrintedSet& set,
                          std::vector<Scene>* scenes) {
  StereoCalibration calib;
  if (o.recorded == nullptr) {
    SH_RETURN_IF_ERROR(RenderScenes(o.rendered, o.seed, o.camera, set.printed, scenes, &calib));
    return o.save_dir != nullptr ? SaveScenes(o.save_dir, set.models, *scenes) : Status::Ok();
  }
  // The set's calibration (scene folders may hold their own).
  struct stat st_calib {};
  const std::string set_calib = std::string(o.recorded) + "/calib.yaml";
  if (stat(set_calib.c_str(), &st_calib) == 0) {
    const Result<StereoCalibration> c = LoadFrameCalibration(set_calib.c_str());
    if (!c.ok()) return c.status();
    calib = *c;
  }
  return LoadRecorded(o.recorded, calib, set.models, scenes);
}

// The scores of the texture path and of the peer, in total and per background x occlusion row
// (the thesis's table 5.5): correct / missed / false alarms.
struct TexturedScores {
  Score ours, theirs;
  std::vector<std::string> row_names;
  std::vector<Score> row_ours, row_theirs;

  size_t RowOf(const Scene& s) {
    const std::string name = s.background + " " + s.occlusion;
    for (size_t i = 0; i < row_names.size(); ++i) {
      if (row_names[i] == name) return i;
    }
    row_names.push_back(name);
    row_ours.emplace_back();
    row_theirs.emplace_back();
    return row_names.size() - 1;
  }
};

// The scene through the texture path, scored.
Status RunOurs(const PrintedSet& set, const Scene& s, bool verbose,
               texture::TextureRecognizer* recognizer, texture::TextureResult* result,
               TexturedScores* scores) {
  const ConstGrayView l{s.left.data(), s.width, s.height, s.width};
  const ConstGrayView r{s.right.data(), s.width, s.height, s.width};
  SH_RETURN_IF_ERROR(recognizer->Init(s.calib, set.db, texture::TextureRecognizerConfig{}, NowNs));
  SH_RETURN_IF_ERROR(recognizer->Process(l, r, result));
  std::vector<RecognizedPose> found;
  for (const texture::TextureObject& o : result->objects) found.push_back({o.model, o.cam_T_model});
  Score& ours = scores->ours;
  ScoreScene(set.models, s, found, &ours, verbose, "texture");
  ScoreScene(set.models, s, found, &scores->row_ours[scores->RowOf(s)], false, "texture");
  const texture::TextureTimings& t = result->time;
  ours.total_ms.push_back(t.total_ms);
  ours.stage_ms[0].push_back(t.features_ms);
  ours.stage_ms[1].push_back(t.matching_ms);
  ours.stage_ms[2].push_back(t.clustering_ms);
  ours.stage_ms[3].push_back(t.stereo_ms + t.verify_ms);
  return Status::Ok();
}

#ifdef STEREOHASH_OPENCV_PEER
// The scene through the OpenCV peer, scored.
Status RunPeer(const PrintedSet& set, const Scene& s, bool verbose, OpenCvTexturePeer* opencv,
               TexturedScores* scores) {
  const ConstGrayView l{s.left.data(), s.width, s.height, s.width};
  const ConstGrayView r{s.right.data(), s.width, s.height, s.width};
  std::vector<PeerObject> objects;
  PeerTimings pt;
  SH_RETURN_IF_ERROR(opencv->Process(s.calib, l, r, &objects, &pt));
  std::vector<RecognizedPose> peer_found;
  peer_found.reserve(objects.size());
  for (const PeerObject& o : objects) peer_found.push_back({o.model, o.cam_T_model});
  Score& theirs = scores->theirs;
  ScoreScene(set.models, s, peer_found, &theirs, verbose, "opencv");
  ScoreScene(set.models, s, peer_found, &scores->row_theirs[scores->RowOf(s)], false, "opencv");
  theirs.total_ms.push_back(pt.total_ms);
  theirs.stage_ms[0].push_back(pt.features_ms);
  theirs.stage_ms[1].push_back(pt.matching_ms);
  theirs.stage_ms[2].push_back(pt.clustering_ms);
  theirs.stage_ms[3].push_back(pt.stereo_ms);
  return Status::Ok();
}
#endif

// Every scene through the texture path and, with `*peer`, the OpenCV peer (which *peer turns
// off when this build has none).
Status RunScenes(const PrintedSet& set, const std::vector<Scene>& scenes, bool verbose, bool* peer,
                 TexturedScores* scores) {
  auto recognizer = std::make_unique<texture::TextureRecognizer>();
#ifdef STEREOHASH_OPENCV_PEER
  auto opencv = std::make_unique<OpenCvTexturePeer>();
  if (*peer) SH_RETURN_IF_ERROR(opencv->Learn(set.printed, set.build));
#else
  if (*peer) std::printf("(no OpenCV peer in this build)\n");
  *peer = false;
#endif
  auto result = std::make_unique<texture::TextureResult>();
  for (const Scene& s : scenes) {
    SH_RETURN_IF_ERROR(RunOurs(set, s, verbose, recognizer.get(), result.get(), scores));
#ifdef STEREOHASH_OPENCV_PEER
    if (*peer) SH_RETURN_IF_ERROR(RunPeer(set, s, verbose, opencv.get(), scores));
#endif
  }
  return Status::Ok();
}

void PrintTexturedRows(const TexturedScores& scores, bool peer) {
  std::printf("%-14s %7s  %-22s%s\n", "row", "objects", "texture: ok / miss / FA",
              peer ? "  opencv: ok / miss / FA" : "");
  for (size_t i = 0; i < scores.row_names.size(); ++i) {
    const Score& ours = scores.row_ours[i];
    std::printf("%-14s %7d  %5d / %4d / %2d        ", scores.row_names[i].c_str(), ours.objects,
                ours.correct, ours.missed, ours.false_alarms);
    if (peer) {
      const Score& theirs = scores.row_theirs[i];
      std::printf("  %5d / %4d / %2d", theirs.correct, theirs.missed, theirs.false_alarms);
    }
    std::printf("\n");
  }
}

}  // namespace

int RunBenchTextured(int argc, char** argv) {
  TexturedOptions o;
  const int exit_code = ParseTexturedOptions(argc, argv, &o);
  if (exit_code >= 0) return exit_code;
  auto set = std::make_unique<PrintedSet>();
  Status st = LoadPrintedSet(o.models_dir, set.get());
  if (!st.ok()) return Fail(st.message());
  std::vector<Scene> scenes;
  st = LoadTexturedScenes(o, *set, &scenes);
  if (!st.ok()) return Fail(st.message());
  TexturedScores scores;
  st = RunScenes(*set, scenes, o.verbose, &o.peer, &scores);
  if (!st.ok()) return Fail(st.message());
  std::printf("%zu scenes, %s\n", scenes.size(),
              o.recorded != nullptr ? o.recorded : "rendered (held-out seeds)");
  PrintTexturedRows(scores, o.peer);
  PrintScore("texture", scores.ours);
  if (o.peer) PrintScore("opencv", scores.theirs);
  std::printf("(the paper: about 1 s per scene on a 3 GHz CPU, SIFT 0.4 s, matching 0.6 s)\n");
  if (o.json_path != nullptr) {
    std::string json = "{\"command\": \"" + CommandLine(argc, argv) +
                       "\", \"scenes\": " + std::to_string(scenes.size()) +
                       ", \"texture\": " + ScoreJson(scores.ours);
    if (o.peer) json += ", \"opencv\": " + ScoreJson(scores.theirs);
    json += "}\n";
    if (!WriteTextFile(o.json_path, json)) return Fail("cannot write the JSON file");
  }
  return 0;
}

}  // namespace sh::tools
