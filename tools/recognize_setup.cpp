#include "tools/recognize_setup.hpp"

#include <Eigen/Geometry>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "hal/sim/image_files.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/binning.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "recog/image/binning.hpp"
#include "recog/stereo/working_volume.hpp"
#include "tables/input_file.hpp"
#include "tools/command.hpp"
#include "tools/setting_table.hpp"

namespace sh::tools {

const char kRecognizeOptionsHelp[] =
    "  --tables      model set (stereohash tables build --models DIR): each path takes its\n"
    "                section (hash tables, view database, feature database, aspect table);\n"
    "                or a single-kind blob (default: the built-in hash fn 5 tables, unless\n"
    "                --views alone gives the model set)\n"
    "  --views       view database of single-colour parts, in place of the model set's\n"
    "                (a model set or a view database file); needs colour images\n"
    "  --aspects     aspect table of the monocular mode, in place of the model set's (default:\n"
    "                the built-in one)\n"
    "  --table       table.yaml: pose of the table the objects stand on (left camera);\n"
    "                bounds the working volume to the space over it\n"
    "  --budget-ms   time limit for the frame (default 0: none)\n"
    "  --background  force a detector preset: dark or light (default: automatic)\n"
    "  --threads     worker threads, the calling one included (default 0: all cores)\n";

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int64_t CpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
}

OptionResult ParseRecognizeOption(const char* command, const char* option, const char* value,
                                  RecognizeOptions* options) {
  if (std::strcmp(option, "--tables") == 0) {
    options->tables_path = value;
  } else if (std::strcmp(option, "--aspects") == 0) {
    options->aspects_path = value;
  } else if (std::strcmp(option, "--views") == 0) {
    options->views_path = value;
  } else if (std::strcmp(option, "--table") == 0) {
    options->table_path = value;
  } else if (std::strcmp(option, "--budget-ms") == 0) {
    double v = 0.0;
    if (!ParseNumber(value, 0.0, 1e6, &v)) {
      std::fprintf(stderr, "stereohash %s: --budget-ms needs a number 0..1e6, got %s\n", command,
                   value);
      return OptionResult::kBadValue;
    }
    options->budget_ms = static_cast<float>(v);
  } else if (std::strcmp(option, "--threads") == 0) {
    char* end = nullptr;
    const long v = std::strtol(value, &end, 10);
    if (end == value || *end != '\0' || v < 0 || v > kMaxPoolThreads) {
      std::fprintf(stderr, "stereohash %s: --threads needs a number 0..%d, got %s\n", command,
                   kMaxPoolThreads, value);
      return OptionResult::kBadValue;
    }
    options->threads = static_cast<int>(v);
  } else if (std::strcmp(option, "--background") == 0) {
    if (std::strcmp(value, "dark") != 0 && std::strcmp(value, "light") != 0) {
      std::fprintf(stderr, "stereohash %s: --background is dark or light, got %s\n", command,
                   value);
      return OptionResult::kBadValue;
    }
    options->background = value;
  } else {
    return OptionResult::kNotMine;
  }
  return OptionResult::kTaken;
}

namespace {

// Reads a whole small text file; kOutOfRange past `limit` bytes.
Status ReadSmallFile(const char* path, const char* what, size_t limit, std::vector<char>* text) {
  text->assign(limit, 0);
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path, what, text->data(), text->size(), &n));
  text->resize(n);
  return Status::Ok();
}

// A string as a JSON string literal's contents: quotes, backslashes and control characters
// escaped.
std::string JsonEscape(const std::string& text) {
  std::string out(6 * text.size() + 1, '\0');
  JsonEscaped(text.data(), text.size(), &out[0], out.size());
  out.resize(std::strlen(out.c_str()));
  return out;
}

}  // namespace

Result<StereoCalibration> LoadCalibration(const char* path) {
  std::vector<char> text;
  SH_RETURN_IF_ERROR(ReadSmallFile(path, "calibration", kMaxCalibrationYamlBytes, &text));
  Result<StereoCalibration> calib = ParseCalibrationYaml(text.data(), text.size());
  if (!calib.ok()) return calib.status().WithContext("calibration %s", path);
  return calib;
}

Result<RigidTransform> LoadTablePose(const char* path) {
  std::vector<char> text;
  SH_RETURN_IF_ERROR(ReadSmallFile(path, "table file", kMaxTableYamlBytes, &text));
  Result<RigidTransform> pose = ParseTableYaml(text.data(), text.size());
  if (!pose.ok()) return pose.status().WithContext("table file %s", path);
  return pose;
}

Result<StereoCalibration> LoadFrameCalibration(const char* path) {
  Result<StereoCalibration> calib = LoadCalibration(path);
  if (!calib.ok()) return calib;
  Result<StereoCalibration> frames = FrameCalibration(*calib);
  if (!frames.ok()) return frames.status().WithContext("%s", path);
  return frames;
}

Status LoadImage(const char* path, const char* which, LoadedImage* out) {
  out->pixels.assign(kMaxSensorPixels * 3, 0);
  const Result<hal::ImageInfo> info =
      hal::ReadImageFile(path, hal::PixelFormat::kRgb8, out->pixels.data(), out->pixels.size());
  if (!info.ok()) return info.status().WithContext("%s image %s", which, path);
  const Result<int> bin = BinFactorFor(info->width, info->height);
  if (!bin.ok()) return bin.status().WithContext("%s image %s", which, path);
  out->bin = *bin;
  out->file_width = info->width;
  out->file_height = info->height;
  const int w = BinnedSize(info->width, *bin), h = BinnedSize(info->height, *bin);
  if (*bin > 1) {
    const ImageView<const Rgb8> full{reinterpret_cast<const Rgb8*>(out->pixels.data()), info->width,
                                     info->height, info->width};
    std::vector<uint8_t> binned(static_cast<size_t>(w) * h * 3);
    SH_RETURN_IF_ERROR(BinRgb(full, *bin, {reinterpret_cast<Rgb8*>(binned.data()), w, h, w}));
    out->pixels.swap(binned);
  }
  const size_t n = static_cast<size_t>(w) * h;
  const ImageView<const Rgb8> rgb{reinterpret_cast<const Rgb8*>(out->pixels.data()), w, h, w};
  out->grey.assign(n, 0);
  const GrayView grey{out->grey.data(), w, h, w};
  SH_RETURN_IF_ERROR(FrameToGray(FrameView::Rgb(rgb), grey));
  out->view = grey;
  // Grey files (grey replicated into RGB by the decoder) stay grey frames.
  out->frame = info->file_channels <= 2 ? FrameView::Gray(grey) : FrameView::Rgb(rgb);
  return Status::Ok();
}

void PrintBinning(const LoadedImage& image) {
  if (image.bin <= 1) return;
  std::printf("image %dx%d binned %d x %d to %dx%d (the calibration alike)\n", image.file_width,
              image.file_height, image.bin, image.bin, image.view.width, image.view.height);
}

Status LoadTables(const RecognizeOptions& options, LoadedTables* out) {
  // A model set gives each path its section: the hash tables and, unless --views names
  // another file, the colour parts' view database.
  uint32_t kinds = 0;
  if (options.tables_path != nullptr) {
    const Result<uint32_t> k = FileBlobKinds(options.tables_path);
    if (!k.ok()) return k.status().WithContext("tables");
    kinds = *k;
  }
  const char* views_path = options.views_path;
  if (views_path == nullptr && (kinds & KindBit(SectionKind::kShapeViews)) != 0) {
    views_path = options.tables_path;
  }
  if (views_path != nullptr) {
    const Status s = out->views.Open(views_path);
    if (!s.ok()) return s;  // names the view database and its path
    // Colour parts only: no hash tables, not even the built-in ones.
    if (options.tables_path == nullptr || (kinds & KindBit(SectionKind::kHash3d)) == 0) {
      return Status::Ok();
    }
  }
  if (options.tables_path != nullptr) {
    const Status s = out->mapped.Open(options.tables_path);
    if (!s.ok()) return s.WithContext("tables %s", options.tables_path);
    out->view = out->mapped.view();
    return Status::Ok();
  }
  const Result<TableView> builtin = OpenDefaultTable();
  if (!builtin.ok()) return builtin.status().WithContext("built-in tables");
  out->view = *builtin;
  return Status::Ok();
}

PipelineConfig MakePipelineConfig(const RecognizeOptions& options, const TableChoice& table) {
  PipelineConfig config = options.background == nullptr  ? PipelineConfig::Automatic()
                          : options.background[0] == 'l' ? PipelineConfig::LightBackground()
                                                         : PipelineConfig::DarkBackground();
  if (table.present) {
    config.stereo.volume = WorkingVolume::OverTable(table.left_T_table);
    config.table.known = true;
    config.table.left_T_table = table.left_T_table;
  }
  config.threads = options.threads;
  return config;
}

namespace {

void LogRecognition(const char* line) { std::fprintf(stderr, "stereohash recognize: %s\n", line); }

}  // namespace

ObjectRecognizerConfig MakeRecognizerConfig(const RecognizeOptions& options,
                                            const TableChoice& table,
                                            const RigidTransform* rig_T_table) {
  ObjectRecognizerConfig config;
  config.automatic = options.background == nullptr;
  config.light_background = options.background != nullptr && options.background[0] == 'l';
  config.threads = options.threads;
  config.table_known = table.present;
  config.volume_over_table = table.present;
  config.table_carry = false;
  if (table.present) {
    config.left_T_table = table.left_T_table;
  } else if (rig_T_table != nullptr) {
    config.left_T_table = *rig_T_table;
  }
  config.mono_table_known = table.present || rig_T_table != nullptr;
  config.aspects_file =
      options.aspects_path != nullptr ? options.aspects_path : options.tables_path;
  config.now_ns = &NowNs;
  config.log = &LogRecognition;
  return config;
}

namespace {

// The settings worth exploring from the bench commands, one entry each.
constexpr Setting<PipelineConfig> kPipelineSettings[] = {
    {"shape.neck_ratio", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.neck_ratio = v; }},
    {"shape.merger_area_ratio", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.merger_area_ratio = v; }},
    {"shape.min_edge_score", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.min_edge_score = v; }},
    {"shape.max_background_share", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.max_background_share = v; }},
    {"shape.views_per_image", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.shape.views_per_image = static_cast<int>(v); }},
    {"shape.fine_hypotheses", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.shape.fine_hypotheses = static_cast<int>(v); }},
    {"shape.max_extent_ratio", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.max_extent_ratio = v; }},
    {"shape.weak_edge_score", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.weak_edge_score = v; }},
    {"shape.restart_deg", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.restart_deg = v; }},
    {"shape.second_pass", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.shape.second_pass = v != 0; }},
    {"shape.second_pass_starts", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.shape.second_pass_starts = static_cast<int>(v); }},
    {"shape.second_pass_min_score", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.second_pass_min_score = v; }},
    {"shape.rounds", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.shape.rounds = static_cast<int>(v); }},
    {"shape.explained_share", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.shape.explained_share = v; }},
    {"verify.min_fraction", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.min_fraction = v; }},
    {"recognizer.defer_below_score", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.defer_below_score = v; }},
    {"verify.max_distance_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.max_distance_px = v; }},
    {"verify.max_angle_deg", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.max_angle_deg = v; }},
    {"verify.min_samples", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.verify.min_samples = static_cast<int>(v); }},
    {"verify.faint_edges", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.verify.faint_edges = v != 0; }},
    {"verify.faint_min_step", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.faint_min_step = v; }},
    {"verify.faint_min_step_sigmas", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.faint_min_step_sigmas = v; }},
    {"verify.faint_snr", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.verify.faint_snr = v; }},
    {"recognizer.vote_threshold", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.vote_threshold = v; }},
    {"recognizer.max_fruitless_bases", SettingKind::kCount,
     [](float v, PipelineConfig& c) {
       c.recognizer.max_fruitless_bases = static_cast<uint32_t>(v);
     }},
    {"recognizer.basis_cell_rank_penalty", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.basis_cell_rank_penalty = v; }},
    {"recognizer.basis_cell_size_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.basis_cell_size_mm = v; }},
    {"recognizer.sigma_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) {
       c.recognizer.sigma_point_mm = c.recognizer.sigma_line_mm = v;
     }},
    {"recognizer.hypotheses_per_basis", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.recognizer.hypotheses_per_basis = static_cast<int>(v); }},
    {"recognizer.compete_vote_factor", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.compete_vote_factor = v; }},
    {"recognizer.compete_extra_matches", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.recognizer.compete_extra_matches = static_cast<int>(v); }},
    {"recognizer.compete_bases", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.recognizer.compete_bases = static_cast<int>(v); }},
    {"recognizer.compete_evidence_margin", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.compete_evidence_margin = v; }},
    {"recognizer.compete_score_margin", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.recognizer.compete_score_margin = v; }},
    {"stereo.epipolar_tolerance_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.stereo.epipolar_tolerance_px = v; }},
    {"stereo.min_plane_angle_deg", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.stereo.min_plane_angle_deg = v; }},
    {"stereo.min_overlap_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.stereo.min_overlap_mm = v; }},
    {"stereo.max_ray_gap_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.stereo.max_ray_gap_mm = v; }},
    {"features.corner_sigma_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.corners.sigma_px = v; }},
    {"features.corner_threshold", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.corners.threshold = v; }},
    {"features.canny_sigma_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.canny.sigma_px = v; }},
    {"features.canny_low", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.canny.low_threshold = v; }},
    {"features.canny_high", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.canny.high_threshold = v; }},
    {"features.canny_texture_factor", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.canny.texture_factor = v; }},
    {"features.adaptive", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.features.adaptive = v != 0.0f; }},
    {"features.edge_snr", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.edge_snr = v; }},
    {"features.corner_snr", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.corner_contrast_snr = v; }},
    {"features.corner_min_contrast", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.features.corner_min_contrast = v; }},
    {"table_estimate.enabled", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.table_estimate.enabled = v != 0.0f; }},
    {"table_estimate.search_again", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.table_estimate.search_again = v != 0.0f; }},
    {"table_estimate.first_search_objects", SettingKind::kCount,
     [](float v, PipelineConfig& c) {
       c.table_estimate.first_search_objects = static_cast<uint32_t>(v);
     }},
    {"table_estimate.min_objects", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.table_estimate.min_objects = static_cast<uint32_t>(v); }},
    {"table_estimate.tolerance_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.table_estimate.tolerance_mm = v; }},
    {"table_carry.enabled", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.table_carry.enabled = v != 0.0f; }},
    {"table_carry.confirm_frames", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.table_carry.confirm_frames = static_cast<uint32_t>(v); }},
    {"table_carry.check_every_frames", SettingKind::kCount,
     [](float v, PipelineConfig& c) {
       c.table_carry.check_every_frames = static_cast<uint32_t>(v);
     }},
    {"table_carry.tolerance_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.table_carry.tolerance_mm = v; }},
    {"table_carry.tolerance_deg", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.table_carry.tolerance_deg = v; }},
    {"rescue.enabled", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.rescue.enabled = v != 0.0f; }},
    {"rescue.min_free_corners", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.rescue.min_free_corners = static_cast<int>(v); }},
    {"rescue.margin_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.rescue.margin_px = v; }},
    {"rescue.corner_radius_px", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.rescue.corner_radius_px = v; }},
    {"rescue.max_scene_bases", SettingKind::kCount,
     [](float v, PipelineConfig& c) { c.rescue.max_scene_bases = static_cast<uint32_t>(v); }},
    {"rescue.max_above_table_mm", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.rescue.max_above_table_mm = v; }},
    {"rescue.right_image", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.rescue.right_image = v != 0.0f; }},
    {"rescue.edge_fit", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.rescue.edge_fit = v != 0.0f; }},
    {"second_look.floor", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.second_look.floor = v; }},
    {"second_look.refit_weak", SettingKind::kFlag,
     [](float v, PipelineConfig& c) { c.second_look.refit_weak = v != 0.0f; }},
    {"second_look.strong", SettingKind::kReal,
     [](float v, PipelineConfig& c) { c.second_look.strong = v; }},
};

}  // namespace

Status ApplyPipelineSetting(const char* setting, PipelineConfig* config) {
  return ApplySetting(setting, kPipelineSettings, config);
}

std::string PipelineSettingNames(const char* indent, size_t width) {
  return SettingNames(kPipelineSettings, indent, width);
}

Result<TableChoice> LoadTableChoice(const char* path) {
  TableChoice table;
  if (path == nullptr) return table;
  const Result<RigidTransform> pose = LoadTablePose(path);
  if (!pose.ok()) return pose.status();
  table.present = true;
  table.left_T_table = *pose;
  table.source = path;
  return table;
}

std::string PoseJsonFields(const char* model_name, const RigidTransform& cam_T_model) {
  const Eigen::Matrix3f& R = cam_T_model.R;
  const Eigen::Vector3f& t = cam_T_model.t_mm;
  char buffer[512];
  char name[kJsonNameBytes];
  std::snprintf(buffer, sizeof(buffer),
                "\"model\": \"%s\", \"R\": [[%.7f, %.7f, %.7f], [%.7f, %.7f, %.7f], [%.7f, "
                "%.7f, %.7f]], \"t\": [%.4f, %.4f, %.4f]",
                JsonEscaped(model_name, kJsonNameBytes, name, sizeof(name)), R(0, 0), R(0, 1),
                R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(), t.z());
  return buffer;
}

std::string ObjectJson(const char* model_name, const RecognizedObject& o) {
  char buffer[128];
  std::snprintf(buffer, sizeof(buffer), ", \"vote\": %.4f, \"verify\": [%.4f, %.4f]}", o.vote,
                o.verify_score[0], o.verify_score[1]);
  return "{" + PoseJsonFields(model_name, o.cam_T_model) + buffer;
}

void PrintObjectLine(size_t index, const char* model_name, const RecognizedObject& o) {
  const Eigen::AngleAxisf aa(o.cam_T_model.R);
  const Eigen::Vector3f rv = aa.axis() * aa.angle() * 57.29577951f;  // radians to degrees
  const Eigen::Vector3f& t = o.cam_T_model.t_mm;
  std::printf("  %-2zu %-10s %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %6.3f %6.3f %6.3f\n", index,
              model_name, t.x(), t.y(), t.z(), rv.x(), rv.y(), rv.z(), o.vote, o.verify_score[0],
              o.verify_score[1]);
}

// The estimated plane (normal towards the cameras, a point of it: the table frame's origin), its
// support and the outcome, as JSON members without braces.
std::string TableEstimateJson(const PipelineResult& r) {
  const TableEstimate& e = r.table_estimate;
  char buffer[768];
  int n = std::snprintf(buffer, sizeof(buffer),
                        "\"estimate\": \"%s\", \"objects\": %u, \"resting\": %u",
                        TableEstimateOutcomeName(e.outcome), e.objects, e.resting);
  if (e.accepted()) {
    const Eigen::Vector3f nz = e.left_T_table.R.col(2);
    const Eigen::Matrix3f& R = e.left_T_table.R;
    const Eigen::Vector3f& t = e.left_T_table.t_mm;
    std::snprintf(buffer + n, sizeof(buffer) - size_t(n),
                  ", \"corners\": %u, \"rms_mm\": %.3f, \"normal\": [%.6f, %.6f, %.6f], "
                  "\"camera_height_mm\": %.3f, \"R\": [[%.7f, %.7f, %.7f], [%.7f, %.7f, %.7f], "
                  "[%.7f, %.7f, %.7f]], \"t\": [%.4f, %.4f, %.4f], \"dropped\": %u",
                  e.corners, e.rms_mm, nz.x(), nz.y(), nz.z(), -nz.dot(t), R(0, 0), R(0, 1),
                  R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(),
                  t.z(), r.table_dropped);
  }
  return buffer;
}

std::string ResultJson(const ModelSet& models, const PipelineResult& r, const TableChoice& table,
                       int threads) {
  // The frame of the poses, as the firmware's results name it: recognize reports the left
  // camera's.
  std::string json = "{\"frame\": \"camera\", \"objects\": [";
  char buffer[1024];
  for (size_t i = 0; i < r.objects.size(); ++i) {
    json += (i ? ", " : "") + ObjectJson(models.model(r.objects[i].model).name, r.objects[i]);
  }
  std::snprintf(buffer, sizeof(buffer),
                "], \"features\": {\"points2d\": [%u, %u], \"lines2d\": [%u, %u], \"points3d\": "
                "%u, \"lines3d\": %u}, \"recognition\": {\"scene_bases_tried\": %u, "
                "\"hypotheses\": %u, \"verifications\": %u, \"held_back\": %u, "
                "\"held_back_accepted\": %u, \"second_looks\": %u, \"budget_exhausted\": %s}, "
                "\"rescue\": {\"ran\": %s, \"ran_right\": %s, \"found\": %u, \"added\": %u}, ",
                r.points2d[0], r.points2d[1], r.lines2d[0], r.lines2d[1], r.points3d, r.lines3d,
                r.recognition.scene_bases_tried, r.recognition.hypotheses,
                r.recognition.verifications, r.recognition.deferred,
                r.recognition.deferred_accepted, r.second_looks,
                r.recognition.budget_exhausted ? "true" : "false", r.rescue.ran ? "true" : "false",
                r.rescue.ran_right ? "true" : "false", r.rescue.found, r.rescue.added);
  json += buffer;
  const DetectionChoice* d = r.detection;
  std::snprintf(buffer, sizeof(buffer),
                "\"detection\": {\"mode\": \"%s\", \"noise_sigma\": [%.3f, %.3f], "
                "\"canny_thresholds\": [[%.3f, %.3f], [%.3f, %.3f]], \"corner_threshold\": "
                "[%.3g, %.3g], \"textured_blocks\": [%u, %u], \"blocks\": %u}, ",
                d[0].adaptive ? "automatic" : "preset", d[0].noise_sigma, d[1].noise_sigma,
                d[0].canny_low, d[0].canny_high, d[1].canny_low, d[1].canny_high,
                d[0].corner_threshold, d[1].corner_threshold, d[0].textured_blocks,
                d[1].textured_blocks, d[0].texture_blocks);
  json += buffer;
  if (table.present) {
    const Eigen::Matrix3f& R = table.left_T_table.R;
    const Eigen::Vector3f& t = table.left_T_table.t_mm;
    std::snprintf(buffer, sizeof(buffer),
                  "\"table\": {\"source\": \"file\", \"file\": \"%s\", \"R\": [[%.7f, %.7f, "
                  "%.7f], [%.7f, %.7f, %.7f], [%.7f, %.7f, %.7f]], \"t\": [%.4f, %.4f, %.4f]}, ",
                  JsonEscape(table.source).c_str(), R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1),
                  R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(), t.z());
    json += buffer;
  } else if (r.table_source == TableSource::kEstimated) {
    json += "\"table\": {\"source\": \"estimated\", " + TableEstimateJson(r) + "}, ";
  } else if (r.table_source == TableSource::kCarried) {
    // The plane of earlier frames (PipelineConfig::table_carry), checked on this one.
    const TableCarry& c = r.table_carry;
    const Eigen::Vector3f nz = c.left_T_table().R.col(2);
    const Eigen::Vector3f& t = c.left_T_table().t_mm;
    std::snprintf(buffer, sizeof(buffer),
                  "\"table\": {\"source\": \"carried\", \"agreeing\": %u, \"resting\": %u, "
                  "\"objects\": %zu, \"normal\": [%.6f, %.6f, %.6f], \"camera_height_mm\": %.3f, "
                  "\"t\": [%.4f, %.4f, %.4f], \"dropped\": %u}, ",
                  c.agreeing(), r.table_resting, r.objects.size(), nz.x(), nz.y(), nz.z(),
                  -nz.dot(t), t.x(), t.y(), t.z(), r.table_dropped);
    json += buffer;
  } else {
    json += "\"table\": {\"source\": \"none\"";
    // A refused estimate says why and what it saw.
    if (r.table_estimate.outcome != TableEstimateOutcome::kDisabled) {
      json += ", " + TableEstimateJson(r);
    }
    json += "}, ";
  }
  std::snprintf(buffer, sizeof(buffer),
                "\"time_ms\": {\"features\": %.3f, \"stereo\": %.3f, \"hashing\": %.3f, "
                "\"verify\": %.3f, \"refine\": %.3f, \"table\": %.3f, \"rescue\": %.3f, "
                "\"total\": %.3f}, \"threads\": %d}\n",
                r.time.features_ms, r.time.stereo_ms, r.time.hashing_ms, r.time.verify_ms,
                r.time.refine_ms, r.time.table_ms, r.time.rescue_ms, r.time.total_ms, threads);
  json += buffer;
  return json;
}

}  // namespace sh::tools
