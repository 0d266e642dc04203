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
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/recognition_paths.hpp"
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
// had, else the board's own table (rig_table.yaml, config->left_T_table then), else the left
// camera. The replay then bounds the scene as the board did and gives the recorded poses.
Status ApplyRecordedVolume(const RecordedVolume& v, bool table_pose_known,
                           ObjectRecognizerConfig* config) {
  if (!v.present) return Status::Ok();
  if (v.in_table_frame && !table_pose_known) {
    return Status::Error(StatusCode::kNotFound,
                         "the recording's volume is in the table frame, but it has neither "
                         "table.yaml nor rig_table.yaml (give the table with --table)");
  }
  config->volume_set = true;
  config->volume_in_table_frame = v.in_table_frame;
  for (int k = 0; k < 3; ++k) {
    config->volume_min_mm[k] = v.min_mm[k];
    config->volume_max_mm[k] = v.max_mm[k];
  }
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
      "corner threshold %.2g / %.2g",
      d[0].adaptive ? "automatic" : "preset", d[0].noise_sigma, d[1].noise_sigma, d[0].canny_low,
      d[0].canny_high, d[1].canny_low, d[1].canny_high, d[0].corner_threshold,
      d[1].corner_threshold);
  if (d[0].texture_blocks > 0) {
    std::printf("; raised over texture in %u / %u of %u blocks", d[0].textured_blocks,
                d[1].textured_blocks, d[0].texture_blocks);
  }
  std::printf("\n");
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
  std::printf(
      "recognition: %u of %u scene bases tried, %u hypotheses, %u verified (%u on a second "
      "look), %u accepted (%u of %u weakly confirmed places held back to the end)\n",
      r.recognition.scene_bases_tried, r.recognition.scene_bases_available,
      r.recognition.hypotheses, r.recognition.verifications, r.second_looks, r.recognition.accepted,
      r.recognition.deferred_accepted, r.recognition.deferred);
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

// The command line: the images, the calibration and where the results go.
struct Invocation {
  const char* calib_path = nullptr;
  const char* left_path = nullptr;
  const char* right_path = nullptr;
  const char* json_path = nullptr;
  const char* overlay_path = nullptr;
  const char* features_overlay_path = nullptr;
  const char* scene_dir = nullptr;
  const char* monocular = nullptr;
  RecognizeOptions options;
};

// Reads the options into *run; false with *exit_code set when the command ends here (--help, a
// bad option).
bool ParseInvocation(int argc, char** argv, Invocation* run, int* exit_code) {
  for (int i = 1; i < argc; ++i) {
    const char *arg = nullptr, *value = nullptr;
    if (!NextOption("recognize", argc, argv, PrintHelp, &i, &arg, &value, exit_code)) return false;
    const OptionResult common = ParseRecognizeOption("recognize", arg, value, &run->options);
    if (common == OptionResult::kBadValue) {
      *exit_code = 2;
      return false;
    }
    if (common == OptionResult::kTaken) continue;
    const char** target = std::strcmp(arg, "--calib") == 0     ? &run->calib_path
                          : std::strcmp(arg, "--left") == 0    ? &run->left_path
                          : std::strcmp(arg, "--right") == 0   ? &run->right_path
                          : std::strcmp(arg, "--json") == 0    ? &run->json_path
                          : std::strcmp(arg, "--overlay") == 0 ? &run->overlay_path
                          : std::strcmp(arg, "--overlay-features") == 0
                              ? &run->features_overlay_path
                          : std::strcmp(arg, "--scene") == 0 ? &run->scene_dir
                                                             : nullptr;
    if (target == nullptr && std::strcmp(arg, "--monocular") == 0 &&
        (std::strcmp(value, "left") == 0 || std::strcmp(value, "right") == 0)) {
      target = &run->monocular;
    }
    if (target == nullptr) {
      std::fprintf(stderr, "stereohash recognize: bad option or value: %s %s (see --help)\n", arg,
                   value);
      *exit_code = 2;
      return false;
    }
    *target = value;
  }
  return true;
}

// A recorded pair (--scene): its images, and the calibration, table, model set and preset it was
// recorded with unless the options give them. Returns the exit code, 0 to go on.
int TakeRecording(Invocation* run, RecordedPair* recorded) {
  if (run->left_path != nullptr || run->right_path != nullptr) {
    std::fprintf(stderr, "stereohash recognize: --scene replaces --left and --right\n");
    return 2;
  }
  const Status found = FindRecordedPair(run->scene_dir, recorded);
  if (!found.ok()) return Fail("%s", found.message());
  // A pair recorded on one camera holds that camera's image alone: recognised from it.
  if (!recorded->left.empty()) run->left_path = recorded->left.c_str();
  if (!recorded->right.empty()) run->right_path = recorded->right.c_str();
  if (run->calib_path == nullptr && recorded->calib.empty()) {
    return Fail("no calib.yaml beside %s (give the calibration with --calib)", run->scene_dir);
  }
  if (run->calib_path == nullptr) run->calib_path = recorded->calib.c_str();
  RecognizeOptions& options = run->options;
  if (options.table_path == nullptr && !recorded->table.empty()) {
    options.table_path = recorded->table.c_str();
  }
  // The recording's model set unless --tables gives one: the models as recorded, if the file is
  // still the one recorded.
  if (options.tables_path == nullptr) {
    if (!recorded->tables.empty()) options.tables_path = recorded->tables.c_str();
    const Status same = CheckRecordedTables(*recorded, options.tables_path);
    if (!same.ok()) return Fail("%s", same.message());
  }
  // The recording's preset unless --background gives one: the poses as recorded.
  if (options.background == nullptr && !recorded->background.empty()) {
    options.background = recorded->background.c_str();
  }
  return 0;
}

// One image (--monocular, or only one of --left and --right).
int RunOneCamera(Invocation* run, const RecordedPair& recorded) {
  if (run->calib_path == nullptr) {
    std::fprintf(stderr, "stereohash recognize: --calib is required (see --help)\n");
    return 2;
  }
  const int camera = run->monocular[0] == 'l' ? 0 : 1;
  const char* image_path = camera == 0 ? run->left_path : run->right_path;
  if (image_path == nullptr) {
    std::fprintf(stderr, "stereohash recognize: --monocular %s needs the %s image\n",
                 run->monocular, run->monocular);
    return 2;
  }
  // A recording made on one camera without a table file: the board laid its objects onto its own
  // table (rig_table.yaml), and so does the replay.
  if (run->options.table_path == nullptr && !recorded.rig_table.empty()) {
    run->options.table_path = recorded.rig_table.c_str();
  }
  return RunMonocular(run->calib_path, image_path, camera, run->options, run->json_path,
                      run->overlay_path);
}

// What the stereo path needs besides the images: the calibration, the table pose (--table, else
// a recording's rig table, which only the rescue uses) and the model set.
struct StereoSetup {
  StereoCalibration calib;
  TableChoice table;
  bool rig_table = false;
  RigidTransform rig_T_table;
  LoadedTables tables;
  MappedFeatureDb printed;    // the printed models, when the set holds them
  bool printed_only = false;  // ... and nothing else: no tables loaded
};

Status LoadStereoSetup(const Invocation& run, const RecordedPair& recorded, StereoSetup* setup) {
  SH_ASSIGN_OR_RETURN(setup->calib, LoadFrameCalibration(run.calib_path));
  const RecognizeOptions& options = run.options;
  if (options.table_path != nullptr) {
    SH_ASSIGN_OR_RETURN(setup->table.left_T_table, LoadTablePose(options.table_path));
    setup->table.present = true;
    setup->table.source = options.table_path;
  }
  // A recording made without a table file: the board's own table bounded its volume and served
  // its one-image rescue, so it does the same here (it is no table pose of the scene).
  setup->rig_table = !setup->table.present && !recorded.rig_table.empty();
  if (setup->rig_table) {
    SH_ASSIGN_OR_RETURN(setup->rig_T_table, LoadTablePose(recorded.rig_table.c_str()));
  }
  if (options.tables_path != nullptr) {
    const Result<uint32_t> kinds = FileBlobKinds(options.tables_path);
    if (!kinds.ok()) return kinds.status().WithContext("tables");
    if ((*kinds & KindBit(SectionKind::kTextureFeatures)) != 0) {
      SH_RETURN_IF_ERROR(setup->printed.Open(options.tables_path));
      const uint32_t others = KindBit(SectionKind::kHash3d) | KindBit(SectionKind::kShapeViews);
      setup->printed_only = options.views_path == nullptr && (*kinds & others) == 0;
      if (setup->printed_only) return Status::Ok();
    }
  }
  return LoadTables(options, &setup->tables);
}

// Colour parts are found by their colour alone: in grey images the path finds nothing, which
// would read as "0 objects" with nothing said.
void WarnGreyForColourParts(const ModelSet& models, const LoadedImage& left,
                            const LoadedImage& right) {
  if (models.shape_count() == 0) return;
  if (left.frame.format != FrameFormat::kGray8 && right.frame.format != FrameFormat::kGray8) return;
  std::fprintf(stderr,
               "stereohash recognize: warning: the model set holds %u colour parts, but the "
               "images are grey: colour parts cannot be found in them\n",
               models.shape_count());
}

// The printed, JSON and overlay outputs of a stereo pair recognised by `recognizer`.
int ReportStereo(const Invocation& run, const StereoSetup& setup,
                 const ObjectRecognizer& recognizer, const LoadedImage& left,
                 const LoadedImage& right) {
  const PipelineResult& result = recognizer.stereo_result();
  const texture::TextureResult* printed = recognizer.printed_result();
  if (printed != nullptr) PrintTextureObjects(setup.printed.view(), *printed);
  const ModelSet stereo_models = setup.tables.models();
  PrintTable(stereo_models, result);
  std::string json =
      ResultJson(stereo_models, result, setup.table, recognizer.pipeline().threads());
  if (printed != nullptr) {
    // The set's printed models: their results as a "printed" member of the same JSON.
    const std::string printed_json =
        TextureResultJson(setup.printed.view(), *printed, recognizer.pipeline().threads());
    json.insert(json.find_last_of('}'),
                ", \"printed\": " + printed_json.substr(0, printed_json.find_last_of('}') + 1));
  }
  if (run.json_path != nullptr && !WriteTextFile(run.json_path, json)) {
    return Fail("cannot write %s: %s", run.json_path, std::strerror(errno));
  }
  std::vector<uint8_t> rgb;
  int w = 0, h = 0;
  if (run.overlay_path != nullptr) {
    Status s = BuildOverlay(recognizer.pipeline(), result, left.view, right.view, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(run.overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", run.overlay_path, s.message());
  }
  if (run.features_overlay_path != nullptr) {
    Status s = BuildFeatureOverlay(recognizer.pipeline(), left.view, right.view, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(run.features_overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", run.features_overlay_path, s.message());
  }
  return 0;
}

// Both images through the recognition facade, as the board runs them: the printed cartons first
// (hidden from the next paths), the colour parts, the polyhedra and the one-image rescue.
int RunStereo(const Invocation& run, const RecordedPair& recorded) {
  LoadedImage left, right;
  Status s = LoadImage(run.left_path, "left", &left);
  if (s.ok()) s = LoadImage(run.right_path, "right", &right);
  if (!s.ok()) return Fail("%s", s.message());
  PrintBinning(left);
  auto setup = std::make_unique<StereoSetup>();
  s = LoadStereoSetup(run, recorded, setup.get());
  if (!s.ok()) return Fail("%s", s.message());
  const bool printed = !setup->printed.view().empty();
  if (setup->printed_only) {
    // Printed models alone: the texture path's own report.
    TextureRun texture_run;
    texture_run.threads = run.options.threads;
    texture_run.json_path = run.json_path;
    texture_run.overlay_path = run.overlay_path;
    return RecognizePrinted(setup->calib, setup->printed.view(), left.view, right.view,
                            texture_run);
  }
  ObjectRecognizerConfig config = MakeRecognizerConfig(
      run.options, setup->table, setup->rig_table ? &setup->rig_T_table : nullptr);
  s = ApplyRecordedVolume(recorded.volume, setup->table.present || setup->rig_table, &config);
  if (!s.ok()) return Fail("%s", s.message());
  auto paths = MakeZeroed<RecognitionPaths>();  // resident as used (docs/memory.md)
  if (paths == nullptr) return Fail("%s", "cannot allocate the recognition paths");
  s = paths->Allocate(printed, /*one_camera=*/true);
  if (!s.ok()) return Fail("%s", s.message());
  auto recognizer = std::make_unique<ObjectRecognizer>(paths->set(), config);
  const ModelSet models(&setup->tables.view, setup->tables.shape(),
                        printed ? &setup->printed.view() : nullptr);
  s = recognizer->Init(setup->calib, models, ~0u);
  if (!s.ok()) return Fail("%s", s.message());
  WarnGreyForColourParts(models, left, right);
  auto output = std::make_unique<RecognitionOutput>();
  const StereoInput pair{left.frame, right.frame, left.view, right.view};
  s = recognizer->Process(pair, run.options.budget_ms, output.get());
  if (!s.ok()) return Fail("%s", s.message());
  return ReportStereo(run, *setup, *recognizer, left, right);
}

int RunRecognize(int argc, char** argv) {
  Invocation run;
  int exit_code = 0;
  if (!ParseInvocation(argc, argv, &run, &exit_code)) return exit_code;
  RecordedPair recorded;
  if (run.scene_dir != nullptr) {
    exit_code = TakeRecording(&run, &recorded);
    if (exit_code != 0) return exit_code;
  }
  if (run.monocular == nullptr && run.calib_path != nullptr &&
      (run.left_path == nullptr) != (run.right_path == nullptr)) {
    run.monocular = run.left_path != nullptr ? "left" : "right";
  }
  if (run.monocular != nullptr) return RunOneCamera(&run, recorded);
  if (run.calib_path == nullptr || run.left_path == nullptr || run.right_path == nullptr) {
    std::fprintf(stderr,
                 "stereohash recognize: --calib with --left and --right, or --scene, are required "
                 "(see --help)\n");
    return 2;
  }
  return RunStereo(run, recorded);
}

}  // namespace

SH_REGISTER_COMMAND(recognize, "recognise objects in a calibrated stereo pair (PNG/PGM)",
                    RunRecognize);

}  // namespace sh::tools
