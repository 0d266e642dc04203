// `stereohash recognize`: recognises the objects in one calibrated stereo pair (PNG or PGM) and
// prints their poses; optionally writes them as JSON and draws an overlay.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/table_file.hpp"
#include "tools/command.hpp"
#include "tools/overlay.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash recognize --calib CALIB.yaml --left L.png --right R.png\n"
      "                            [--tables TABLES.bin] [--json OUT.json] [--overlay OUT.png]\n"
      "                            [--budget-ms N] [--background dark|light]\n"
      "Recognises the reference objects in a calibrated stereo pair (PNG or PGM, grey or colour)\n"
      "and prints their poses: x_cam = R x_model + t, model and left-camera millimetres.\n"
      "  --tables      hash table file (default: the built-in hash fn 5 tables)\n"
      "  --json        write {\"objects\": [...], \"features\": {...}, \"time_ms\": {...}}\n"
      "  --overlay     write left | right with the recognised models' visible edges (RGB PNG)\n"
      "  --budget-ms   time limit for the frame (default 0: none)\n"
      "  --background  pipeline preset: dark (default) or light\n");
}

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int Fail(const char* fmt, const char* a, const char* b = "") {
  std::fprintf(stderr, "stereohash recognize: ");
  std::fprintf(stderr, fmt, a, b);
  std::fprintf(stderr, "\n");
  return 1;
}

Result<StereoCalibration> LoadCalibration(const char* path) {
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot open calibration %s: %s", path,
                         std::strerror(errno));
  }
  std::vector<char> text(kMaxCalibrationYamlBytes + 1);
  const size_t n = std::fread(text.data(), 1, text.size(), f);
  const bool read_error = std::ferror(f) != 0;
  std::fclose(f);
  if (read_error) {
    return Status::Error(StatusCode::kDataLoss, "cannot read calibration %s", path);
  }
  if (n > kMaxCalibrationYamlBytes) {
    return Status::Error(StatusCode::kOutOfRange, "calibration %s is larger than %zu bytes", path,
                         kMaxCalibrationYamlBytes);
  }
  Result<StereoCalibration> calib = ParseCalibrationYaml(text.data(), n);
  if (!calib.ok()) {
    return Status::Error(calib.status().code(), "calibration %s: %s", path,
                         calib.status().message());
  }
  return calib;
}

struct LoadedImage {
  std::vector<uint8_t> pixels;
  ConstGrayView view;
};

Status LoadImage(const char* path, const char* which, LoadedImage* out) {
  out->pixels.assign(kMaxImagePixels, 0);
  const Result<hal::ImageInfo> info =
      hal::ReadImageFile(path, hal::PixelFormat::kGray8, out->pixels.data(), out->pixels.size());
  if (!info.ok()) {
    return Status::Error(info.status().code(), "%s image %s: %s", which, path,
                         info.status().message());
  }
  out->view = {out->pixels.data(), info->width, info->height, info->width};
  return Status::Ok();
}

bool WriteText(const char* path, const std::string& text) {
  std::FILE* f = std::fopen(path, "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  return std::fclose(f) == 0 && ok;
}

std::string ResultJson(const TableView& table, const PipelineResult& r) {
  std::string json = "{\"objects\": [";
  char buffer[1024];
  for (size_t i = 0; i < r.objects.size(); ++i) {
    const RecognizedObject& o = r.objects[i];
    const Eigen::Matrix3f& R = o.cam_T_model.R;
    const Eigen::Vector3f& t = o.cam_T_model.t_mm;
    std::snprintf(buffer, sizeof(buffer),
                  "%s{\"model\": \"%s\", \"R\": [[%.7f, %.7f, %.7f], [%.7f, %.7f, %.7f], [%.7f, "
                  "%.7f, %.7f]], \"t\": [%.4f, %.4f, %.4f], \"vote\": %.4f, \"verify\": [%.4f, "
                  "%.4f]}",
                  i ? ", " : "", table.model(o.model).name, R(0, 0), R(0, 1), R(0, 2), R(1, 0),
                  R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2), t.x(), t.y(), t.z(), o.vote,
                  o.verify_score[0], o.verify_score[1]);
    json += buffer;
  }
  std::snprintf(buffer, sizeof(buffer),
                "], \"features\": {\"points2d\": [%u, %u], \"lines2d\": [%u, %u], \"points3d\": "
                "%u, \"lines3d\": %u}, \"time_ms\": {\"features\": %.3f, \"stereo\": %.3f, "
                "\"hashing\": %.3f, \"verify\": %.3f, \"total\": %.3f}}\n",
                r.points2d[0], r.points2d[1], r.lines2d[0], r.lines2d[1], r.points3d, r.lines3d,
                r.time.features_ms, r.time.stereo_ms, r.time.hashing_ms, r.time.verify_ms,
                r.time.total_ms);
  json += buffer;
  return json;
}

void PrintTable(const TableView& table, const PipelineResult& r) {
  std::printf("%zu object%s recognised\n", r.objects.size(), r.objects.size() == 1 ? "" : "s");
  if (!r.objects.empty()) {
    std::printf("  %-2s %-10s %28s %28s %6s %13s\n", "#", "model", "t (mm, left camera)",
                "rotation vector (deg)", "vote", "verify l / r");
  }
  for (size_t i = 0; i < r.objects.size(); ++i) {
    const RecognizedObject& o = r.objects[i];
    const Eigen::AngleAxisf aa(o.cam_T_model.R);
    const Eigen::Vector3f rv = aa.axis() * aa.angle() * 57.29577951f;  // radians to degrees
    const Eigen::Vector3f& t = o.cam_T_model.t_mm;
    std::printf("  %-2zu %-10s %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %6.3f %6.3f %6.3f\n", i,
                table.model(o.model).name, t.x(), t.y(), t.z(), rv.x(), rv.y(), rv.z(), o.vote,
                o.verify_score[0], o.verify_score[1]);
  }
  std::printf(
      "features: 2-D points %u / %u, 2-D lines %u / %u (left / right); 3-D points %u, "
      "3-D lines %u%s\n",
      r.points2d[0], r.points2d[1], r.lines2d[0], r.lines2d[1], r.points3d, r.lines3d,
      r.points3d_truncated || r.lines3d_truncated ? " (scene capacity reached)" : "");
  std::printf("recognition: %u of %u scene bases tried, %u hypotheses, %u verified, %u accepted\n",
              r.recognition.scene_bases_tried, r.recognition.scene_bases_available,
              r.recognition.hypotheses, r.recognition.verifications, r.recognition.accepted);
  std::printf(
      "time: features %.1f ms, stereo %.1f ms, hashing %.1f ms, verify %.1f ms, total "
      "%.1f ms%s\n",
      r.time.features_ms, r.time.stereo_ms, r.time.hashing_ms, r.time.verify_ms, r.time.total_ms,
      r.recognition.budget_exhausted ? " (budget exhausted)" : "");
}

int RunRecognize(int argc, char** argv) {
  const char* calib_path = nullptr;
  const char* tables_path = nullptr;
  const char* left_path = nullptr;
  const char* right_path = nullptr;
  const char* json_path = nullptr;
  const char* overlay_path = nullptr;
  float budget_ms = 0;
  bool light = false;
  for (int i = 1; i < argc; ++i) {
    const char *arg = nullptr, *value = nullptr;
    int exit_code = 0;
    if (!NextOption("recognize", argc, argv, PrintHelp, &i, &arg, &value, &exit_code)) {
      return exit_code;
    }
    if (std::strcmp(arg, "--calib") == 0) {
      calib_path = value;
    } else if (std::strcmp(arg, "--tables") == 0) {
      tables_path = value;
    } else if (std::strcmp(arg, "--left") == 0) {
      left_path = value;
    } else if (std::strcmp(arg, "--right") == 0) {
      right_path = value;
    } else if (std::strcmp(arg, "--json") == 0) {
      json_path = value;
    } else if (std::strcmp(arg, "--overlay") == 0) {
      overlay_path = value;
    } else if (std::strcmp(arg, "--budget-ms") == 0) {
      char* end = nullptr;
      const double v = std::strtod(value, &end);
      if (end == value || *end != '\0' || !std::isfinite(v) || v < 0 || v > 1e6) {
        std::fprintf(stderr, "stereohash recognize: --budget-ms needs a number 0..1e6, got %s\n",
                     value);
        return 2;
      }
      budget_ms = static_cast<float>(v);
    } else if (std::strcmp(arg, "--background") == 0 &&
               (std::strcmp(value, "dark") == 0 || std::strcmp(value, "light") == 0)) {
      light = value[0] == 'l';
    } else {
      std::fprintf(stderr, "stereohash recognize: bad option or value: %s %s (see --help)\n", arg,
                   value);
      return 2;
    }
  }
  if (calib_path == nullptr || left_path == nullptr || right_path == nullptr) {
    std::fprintf(stderr,
                 "stereohash recognize: --calib, --left and --right are required (see --help)\n");
    return 2;
  }

  const Result<StereoCalibration> calib = LoadCalibration(calib_path);
  if (!calib.ok()) return Fail("%s", calib.status().message());
  MappedTable mapped;
  TableView table;
  if (tables_path != nullptr) {
    const Status s = mapped.Open(tables_path);
    if (!s.ok()) return Fail("tables %s: %s", tables_path, s.message());
    table = mapped.view();
  } else {
    const Result<TableView> builtin = OpenDefaultTable();
    if (!builtin.ok()) return Fail("built-in tables: %s", builtin.status().message());
    table = *builtin;
  }
  LoadedImage left, right;
  Status s = LoadImage(left_path, "left", &left);
  if (s.ok()) s = LoadImage(right_path, "right", &right);
  if (!s.ok()) return Fail("%s", s.message());

  const PipelineConfig config =
      light ? PipelineConfig::LightBackground() : PipelineConfig::DarkBackground();
  auto pipeline = std::make_unique<Pipeline>();  // ~90 MiB of frame buffers
  s = pipeline->Init(*calib, table, config, NowNs);
  if (!s.ok()) return Fail("%s", s.message());
  auto result = std::make_unique<PipelineResult>();
  s = pipeline->Process(left.view, right.view, budget_ms, result.get());
  if (!s.ok()) return Fail("%s", s.message());

  PrintTable(table, *result);
  if (json_path != nullptr && !WriteText(json_path, ResultJson(table, *result))) {
    return Fail("cannot write %s: %s", json_path, std::strerror(errno));
  }
  if (overlay_path != nullptr) {
    std::vector<uint8_t> rgb;
    int w = 0, h = 0;
    s = BuildOverlay(*pipeline, *result, left.view, right.view, &rgb, &w, &h);
    if (s.ok()) s = WriteRgbPng(overlay_path, rgb.data(), w, h);
    if (!s.ok()) return Fail("overlay %s: %s", overlay_path, s.message());
  }
  return 0;
}

}  // namespace

SH_REGISTER_COMMAND(recognize, "recognise objects in a calibrated stereo pair (PNG/PGM)",
                    RunRecognize);

}  // namespace sh::tools
