// `stereohash recognize`: recognises the objects in one calibrated stereo pair (PNG or PGM) and
// prints their poses; optionally writes them as JSON and draws an overlay.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/stereo/working_volume.hpp"
#include "tools/command.hpp"
#include "tools/mono_setup.hpp"
#include "tools/overlay.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/recognize_texture.hpp"
#include "tools/recorded_pair.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash recognize --calib CALIB.yaml --left L.png --right R.png\n"
      "       stereohash recognize --calib CALIB.yaml --left L.png | --right R.png  (one camera)\n"
      "                            [--json OUT.json] [--overlay OUT.png] [--tables MODELS.bin]\n"
      "                            [--table TABLE.yaml] [--budget-ms N] [--background dark|light]\n"
      "                            [--threads N] [--overlay-features OUT.png]\n"
      "Recognises the reference objects in a calibrated stereo pair (PNG or PGM, grey or colour)\n"
      "and prints their poses: x_cam = R x_model + t, model and left-camera millimetres. With a\n"
      "model set as --tables (`stereohash tables build --models DIR`), every model it holds:\n"
      "polyhedra, colour parts and printed models (docs/texture.md; the printed models' results\n"
      "go into the JSON's \"printed\" member when the set holds other models too, and the\n"
      "overlay then shows the others).\n"
      "  --json        write {\"objects\": [...], \"features\": {...}, \"time_ms\": {...}, ...}\n"
      "  --overlay     write left | right with the recognised models' visible edges (RGB PNG)\n"
      "  --overlay-features  write left | right with what the detectors found: edge pixels\n"
      "                (blue), line segments (yellow), corners (green: paired into a 3-D point)\n"
      "  --scene DIR   a recorded pair instead of --left/--right: DIR/left.png and right.png (or\n"
      "                .pgm) of a recorded-scenes set or a firmware recording; --calib and\n"
      "                --table default to calib.yaml and table.yaml beside DIR; a firmware\n"
      "                recording's settings.conf gives the model set (unless --tables), the\n"
      "                preset (unless --background) and the working volume, its\n"
      "                rig_table.yaml the board's own table; a folder\n"
      "                recorded on one camera holds one image and is recognised from it\n"
      "  --monocular left|right  one camera only (2-D aspect hashing; with --table, objects\n"
      "                rest on the table); also chosen by giving only --left or only --right\n"
      "%s",
      kRecognizeOptionsHelp);
}

int Fail(const char* fmt, const char* a, const char* b = "") {
  std::fprintf(stderr, "stereohash recognize: ");
  std::fprintf(stderr, fmt, a, b);
  std::fprintf(stderr, "\n");
  return 1;
}

// A firmware recording's working volume (settings.conf), in its frame: the table file the board
// had, else the board's own table (rig_table.yaml), else the left camera. The replay then bounds
// the scene as the board did and gives the recorded poses.
Status ApplyRecordedVolume(const RecordedVolume& v, const TableChoice& table,
                           const RigidTransform* rig_T_table, PipelineConfig* config) {
  if (!v.present) return Status::Ok();
  const Eigen::Vector3f min_mm(v.min_mm[0], v.min_mm[1], v.min_mm[2]);
  const Eigen::Vector3f max_mm(v.max_mm[0], v.max_mm[1], v.max_mm[2]);
  if (!v.in_table_frame) {
    config->stereo.volume = WorkingVolume::InLeftCamera(min_mm, max_mm);
    return Status::Ok();
  }
  const RigidTransform* left_T_table = table.present ? &table.left_T_table : rig_T_table;
  if (left_T_table == nullptr) {
    return Status::Error(StatusCode::kNotFound,
                         "the recording's volume is in the table frame, but it has neither "
                         "table.yaml nor rig_table.yaml (give the table with --table)");
  }
  config->stereo.volume = WorkingVolume::InFrame(*left_T_table, min_mm, max_mm);
  return Status::Ok();
}

void PrintTable(const ModelSet& models, const PipelineResult& r) {
  std::printf("%zu object%s recognised\n", r.objects.size(), r.objects.size() == 1 ? "" : "s");
  if (!r.objects.empty()) {
    std::printf("  %-2s %-10s %28s %28s %6s %13s\n", "#", "model", "t (mm, left camera)",
                "rotation vector (deg)", "vote", "verify l / r");
  }
  for (size_t i = 0; i < r.objects.size(); ++i) {
    PrintObjectLine(i, models.model(r.objects[i].model).name, r.objects[i]);
  }
  std::printf(
      "features: 2-D points %u / %u, 2-D lines %u / %u (left / right); 3-D points %u, "
      "3-D lines %u%s\n",
      r.points2d[0], r.points2d[1], r.lines2d[0], r.lines2d[1], r.points3d, r.lines3d,
      r.points3d_truncated || r.lines3d_truncated ? " (scene capacity reached)" : "");
  const DetectionChoice* d = r.detection;
  std::printf(
      "detection: %s; noise %.2f / %.2f grey levels, Canny thresholds %.2f-%.2f / %.2f-%.2f, "
      "corner threshold %.2g / %.2g\n",
      d[0].adaptive ? "automatic" : "preset", d[0].noise_sigma, d[1].noise_sigma, d[0].canny_low,
      d[0].canny_high, d[1].canny_low, d[1].canny_high, d[0].corner_threshold,
      d[1].corner_threshold);
  const TableEstimate& e = r.table_estimate;
  if (r.table_source == TableSource::kEstimated) {
    const Eigen::Vector3f n = e.left_T_table.R.col(2);
    std::printf(
        "table: estimated from the objects found (%u of %u rest on it, rms %.2f mm): normal "
        "(%.4f, %.4f, %.4f), camera %.1f mm over it; %u 3-D features outside the space over it "
        "dropped and the search repeated\n",
        e.resting, e.objects, e.rms_mm, n.x(), n.y(), n.z(), -n.dot(e.left_T_table.t_mm),
        r.table_dropped);
  } else if (r.table_source == TableSource::kNone) {
    std::printf("table: none (estimate: %s, %u of %u objects on one plane)\n",
                TableEstimateOutcomeName(e.outcome), e.resting, e.objects);
  }
  std::printf("recognition: %u of %u scene bases tried, %u hypotheses, %u verified, %u accepted\n",
              r.recognition.scene_bases_tried, r.recognition.scene_bases_available,
              r.recognition.hypotheses, r.recognition.verifications, r.recognition.accepted);
  if (r.rescue.ran) {
    std::printf("rescue (one image, confirmed in both): %u found, %u added, %.1f ms\n",
                r.rescue.found, r.rescue.added, r.time.rescue_ms);
  }
  std::printf(
      "time: features %.1f ms, stereo %.1f ms, hashing %.1f ms, verify %.1f ms, edge fit %.1f "
      "ms, total %.1f ms%s\n",
      r.time.features_ms, r.time.stereo_ms, r.time.hashing_ms, r.time.verify_ms, r.time.refine_ms,
      r.time.total_ms, r.recognition.budget_exhausted ? " (budget exhausted)" : "");
}

// One camera: the monocular pipeline on its image, poses in the left camera's frame.
int RunMonocular(const char* calib_path, const char* image_path, int camera,
                 const RecognizeOptions& options, const char* json_path, const char* overlay_path) {
  const Result<StereoCalibration> calib = LoadFrameCalibration(calib_path);
  if (!calib.ok()) return Fail("%s", calib.status().message());
  const Result<TableChoice> loaded_table = LoadTableChoice(options.table_path);
  if (!loaded_table.ok()) return Fail("%s", loaded_table.status().message());
  const TableChoice& table = *loaded_table;
  LoadedAspects aspects;
  Status s = LoadAspects(options, &aspects, /*required=*/true);
  if (!s.ok()) return Fail("%s", s.message());
  if (!table.present) {
    std::fprintf(stderr,
                 "stereohash recognize: %s: give the table pose with --table TABLE.yaml "
                 "(stereohash calibrate-table), or both images\n",
                 kMonoNeedsTablePlane);
    return 2;
  }
  LoadedImage image;
  s = LoadImage(image_path, camera == 0 ? "left" : "right", &image);
  if (!s.ok()) return Fail("%s", s.message());
  PrintBinning(image);
  auto pipeline = MakeZeroed<MonoPipeline>();
  s = pipeline->Init(*calib, camera, aspects.view, table.present ? &table.left_T_table : nullptr,
                     MakeMonoConfig(options), NowNs);
  if (!s.ok()) return Fail("%s", s.message());
  const CameraIntrinsics& cam = camera == 0 ? calib->left : calib->right;
  auto workspace = MakeWorkspace<FeatureWorkspace>(cam.width, cam.height);
  if (workspace == nullptr) return Fail("%s", "cannot allocate the feature workspace");
  auto result = std::make_unique<MonoResult>();
  s = pipeline->Process(image.view, options.budget_ms, *workspace, result.get());
  if (!s.ok()) return Fail("%s", s.message());
  PrintMonoResult(aspects.view, *result, camera);
  if (json_path != nullptr &&
      !WriteTextFile(json_path, MonoResultJson(aspects.view, *result, table, camera))) {
    return Fail("cannot write %s: %s", json_path, std::strerror(errno));
  }
  if (overlay_path != nullptr) {
    std::vector<uint8_t> rgb;
    int w = 0, h = 0;
    s = BuildMonoOverlay(*pipeline, aspects.view, *result, image.view, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", overlay_path, s.message());
  }
  return 0;
}

int RunRecognize(int argc, char** argv) {
  const char* calib_path = nullptr;
  const char* left_path = nullptr;
  const char* right_path = nullptr;
  const char* json_path = nullptr;
  const char* overlay_path = nullptr;
  const char* features_overlay_path = nullptr;
  const char* scene_dir = nullptr;
  const char* monocular = nullptr;
  RecognizeOptions options;
  for (int i = 1; i < argc; ++i) {
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("recognize", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    const OptionResult common = ParseRecognizeOption("recognize", arg, value, &options);
    if (common == OptionResult::kBadValue) return 2;
    if (common == OptionResult::kTaken) continue;
    if (std::strcmp(arg, "--calib") == 0) {
      calib_path = value;
    } else if (std::strcmp(arg, "--left") == 0) {
      left_path = value;
    } else if (std::strcmp(arg, "--right") == 0) {
      right_path = value;
    } else if (std::strcmp(arg, "--json") == 0) {
      json_path = value;
    } else if (std::strcmp(arg, "--overlay") == 0) {
      overlay_path = value;
    } else if (std::strcmp(arg, "--overlay-features") == 0) {
      features_overlay_path = value;
    } else if (std::strcmp(arg, "--scene") == 0) {
      scene_dir = value;
    } else if (std::strcmp(arg, "--monocular") == 0 &&
               (std::strcmp(value, "left") == 0 || std::strcmp(value, "right") == 0)) {
      monocular = value;
    } else {
      std::fprintf(stderr, "stereohash recognize: bad option or value: %s %s (see --help)\n", arg,
                   value);
      return 2;
    }
  }
  RecordedPair recorded;
  if (scene_dir != nullptr) {
    if (left_path != nullptr || right_path != nullptr) {
      std::fprintf(stderr, "stereohash recognize: --scene replaces --left and --right\n");
      return 2;
    }
    const Status found = FindRecordedPair(scene_dir, &recorded);
    if (!found.ok()) return Fail("%s", found.message());
    // A pair recorded on one camera holds that camera's image alone: recognised from it.
    if (!recorded.left.empty()) left_path = recorded.left.c_str();
    if (!recorded.right.empty()) right_path = recorded.right.c_str();
    if (calib_path == nullptr && recorded.calib.empty()) {
      return Fail("no calib.yaml beside %s (give the calibration with --calib)", scene_dir);
    }
    if (calib_path == nullptr) calib_path = recorded.calib.c_str();
    if (options.table_path == nullptr && !recorded.table.empty()) {
      options.table_path = recorded.table.c_str();
    }
    // The recording's model set unless --tables gives one: the models as recorded, if the file
    // is still the one recorded.
    if (options.tables_path == nullptr) {
      if (!recorded.tables.empty()) options.tables_path = recorded.tables.c_str();
      const Status same = CheckRecordedTables(recorded, options.tables_path);
      if (!same.ok()) return Fail("%s", same.message());
    }
    // The recording's preset unless --background gives one: the poses as recorded.
    if (options.background == nullptr && !recorded.background.empty()) {
      options.background = recorded.background.c_str();
    }
  }
  if (monocular == nullptr && calib_path != nullptr &&
      (left_path == nullptr) != (right_path == nullptr)) {
    monocular = left_path != nullptr ? "left" : "right";
  }
  if (monocular != nullptr) {
    if (calib_path == nullptr) {
      std::fprintf(stderr, "stereohash recognize: --calib is required (see --help)\n");
      return 2;
    }
    const int camera = monocular[0] == 'l' ? 0 : 1;
    const char* image_path = camera == 0 ? left_path : right_path;
    if (image_path == nullptr) {
      std::fprintf(stderr, "stereohash recognize: --monocular %s needs the %s image\n", monocular,
                   monocular);
      return 2;
    }
    // A recording made on one camera without a table file: the board laid its objects onto its
    // own table (rig_table.yaml), and so does the replay.
    if (options.table_path == nullptr && !recorded.rig_table.empty()) {
      options.table_path = recorded.rig_table.c_str();
    }
    return RunMonocular(calib_path, image_path, camera, options, json_path, overlay_path);
  }
  if (calib_path == nullptr || left_path == nullptr || right_path == nullptr) {
    std::fprintf(stderr,
                 "stereohash recognize: --calib with --left and --right, or --scene, are required "
                 "(see --help)\n");
    return 2;
  }

  const Result<StereoCalibration> calib = LoadFrameCalibration(calib_path);
  if (!calib.ok()) return Fail("%s", calib.status().message());
  TableChoice table;
  if (options.table_path != nullptr) {
    const Result<RigidTransform> pose = LoadTablePose(options.table_path);
    if (!pose.ok()) return Fail("%s", pose.status().message());
    table.present = true;
    table.left_T_table = *pose;
    table.source = options.table_path;
  }
  LoadedImage left, right;
  Status s = LoadImage(left_path, "left", &left);
  if (s.ok()) s = LoadImage(right_path, "right", &right);
  if (!s.ok()) return Fail("%s", s.message());
  PrintBinning(left);
  // Printed models (a feature database, alone or as a model set's section) go through the
  // texture path; the polyhedra and colour parts of the same set through the pipeline.
  uint32_t kinds = 0;
  if (options.tables_path != nullptr) {
    const Result<uint32_t> k = FileBlobKinds(options.tables_path);
    if (!k.ok()) return Fail("tables: %s", k.status().message());
    kinds = *k;
  }
  const bool printed = (kinds & KindBit(SectionKind::kTextureFeatures)) != 0;
  const bool others =
      options.views_path != nullptr ||
      (kinds & (KindBit(SectionKind::kHash3d) | KindBit(SectionKind::kShapeViews))) != 0;
  MappedFeatureDb db;
  TextureRun run;
  run.threads = options.threads;
  if (printed) {
    s = db.Open(options.tables_path);
    if (!s.ok()) return Fail("%s", s.message());
    if (!others) {
      run.json_path = json_path;
      run.overlay_path = overlay_path;
      return RecognizePrinted(*calib, db.view(), left.view, right.view, run);
    }
  }
  LoadedTables tables;
  s = LoadTables(options, &tables);
  if (!s.ok()) return Fail("%s", s.message());

  // A recording made without a table file: the board's own table bounded its volume and served
  // its one-image rescue, so it does the same here (it is no table pose of the scene).
  RigidTransform rig_T_table;
  const bool rig_table = !table.present && !recorded.rig_table.empty();
  if (rig_table) {
    const Result<RigidTransform> rig = LoadTablePose(recorded.rig_table.c_str());
    if (!rig.ok()) return Fail("%s", rig.status().message());
    rig_T_table = *rig;
  }
  const RigidTransform* one_camera_table = table.present ? &table.left_T_table
                                           : rig_table   ? &rig_T_table
                                                         : nullptr;
  PipelineConfig config = MakePipelineConfig(options, table);
  s = ApplyRecordedVolume(recorded.volume, table, rig_table ? &rig_T_table : nullptr, &config);
  if (!s.ok()) return Fail("%s", s.message());
  auto pipeline = MakeZeroed<Pipeline>();  // ~118 MiB, resident as used (docs/memory.md)
  s = pipeline->Init(*calib, tables.view, config, NowNs, tables.shape());
  if (!s.ok()) return Fail("%s", s.message());
  // Colour parts are found by their colour alone: in grey images the path finds nothing, which
  // would read as "0 objects" with nothing said.
  if (tables.shape() != nullptr &&
      (left.frame.format == FrameFormat::kGray8 || right.frame.format == FrameFormat::kGray8)) {
    std::fprintf(stderr,
                 "stereohash recognize: warning: the model set holds %u colour parts, but the "
                 "images are grey: colour parts cannot be found in them\n",
                 tables.shape()->model_count());
  }
  // The one-image rescue, with the monocular mode's aspect table when it lists the same models.
  LoadedAspects aspects;
  ZeroedPtr<MonoRecognizer> rescue;
  if (config.rescue.enabled && pipeline->models().hash_count() > 0 &&
      LoadAspects(options, &aspects).ok()) {
    s = LendRescueRecognizer(aspects.view, *calib, one_camera_table, MakeMonoConfig(options).mono,
                             pipeline.get(), &rescue);
    if (!s.ok()) std::fprintf(stderr, "stereohash recognize: no rescue: %s\n", s.message());
  }
  // The printed models first: the cartons found are hidden from the polyhedral path (their
  // edges and print would crowd its features and search), as in the firmware.
  std::string printed_json;
  std::vector<PosedModel> cartons;
  if (printed) {
    run.json_text = &printed_json;
    run.found = &cartons;
    const int rc = RecognizePrinted(*calib, db.view(), left.view, right.view, run);
    if (rc != 0) return rc;
  }
  auto result = std::make_unique<PipelineResult>();
  s = pipeline->Process(left.frame, right.frame, options.budget_ms, result.get(), cartons.data(),
                        cartons.size());
  if (!s.ok()) return Fail("%s", s.message());

  PrintTable(pipeline->models(), *result);
  std::string json = ResultJson(pipeline->models(), *result, table, pipeline->threads());
  if (printed) {
    // The set's printed models: their results as a "printed" member of the same JSON.
    const size_t end = json.find_last_of('}');
    json.insert(end,
                ", \"printed\": " + printed_json.substr(0, printed_json.find_last_of('}') + 1));
  }
  if (json_path != nullptr && !WriteTextFile(json_path, json)) {
    return Fail("cannot write %s: %s", json_path, std::strerror(errno));
  }
  if (overlay_path != nullptr) {
    std::vector<uint8_t> rgb;
    int w = 0, h = 0;
    s = BuildOverlay(*pipeline, *result, left.view, right.view, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", overlay_path, s.message());
  }
  if (features_overlay_path != nullptr) {
    std::vector<uint8_t> rgb;
    int w = 0, h = 0;
    s = BuildFeatureOverlay(*pipeline, left.view, right.view, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(features_overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", features_overlay_path, s.message());
  }
  return 0;
}

}  // namespace

SH_REGISTER_COMMAND(recognize, "recognise objects in a calibrated stereo pair (PNG/PGM)",
                    RunRecognize);

}  // namespace sh::tools
