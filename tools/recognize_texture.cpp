#include "tools/recognize_texture.hpp"

#include <Eigen/Geometry>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "hal/sim/image_files.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/pipeline/worker_pool.hpp"
#include "tools/overlay.hpp"
#include "tools/recognize_setup.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

int Fail(const char* fmt, const char* a, const char* b = "") {
  std::fprintf(stderr, "stereohash recognize: ");
  std::fprintf(stderr, fmt, a, b);
  std::fprintf(stderr, "\n");
  return 1;
}

}  // namespace

void PrintTextureObjects(const FeatureDbView& db, const texture::TextureResult& r) {
  std::printf("%zu printed object%s recognised\n", r.objects.size(),
              r.objects.size() == 1 ? "" : "s");
  if (!r.objects.empty()) {
    std::printf("  %-2s %-10s %28s %28s %13s %5s %7s %6s\n", "#", "model", "t (mm, left camera)",
                "rotation vector (deg)", "print l / r", "faces", "matches", "stereo");
  }
  for (size_t i = 0; i < r.objects.size(); ++i) {
    const texture::TextureObject& o = r.objects[i];
    const Eigen::AngleAxisf aa(o.cam_T_model.R);
    const Eigen::Vector3f rv = aa.axis() * aa.angle() * 57.29577951f;  // radians to degrees
    const Eigen::Vector3f& t = o.cam_T_model.t_mm;
    std::printf("  %-2zu %-10s %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f %6.3f %6.3f %5u %7u %6u\n", i,
                db.model(o.model).name, t.x(), t.y(), t.z(), rv.x(), rv.y(), rv.z(),
                o.print.zncc[0], o.print.zncc[1], o.faces, o.feature_matches, o.stereo_points);
  }
  const texture::TextureStats& s = r.stats;
  std::printf(
      "texture: %u keypoints, %u matches, %u clusters, %u faces in 2-D, %u with a stereo plane, "
      "%u hypotheses, %u rejected\n",
      s.keypoints, s.matches, s.clusters, s.faces_2d, s.faces_3d, s.hypotheses, s.rejected);
  const texture::TextureTimings& t = r.time;
  std::printf(
      "time: features %.1f ms, matching %.1f ms, clustering %.1f ms, stereo %.1f ms, pose and "
      "verification %.1f ms, total %.1f ms\n",
      t.features_ms, t.matching_ms, t.clustering_ms, t.stereo_ms, t.verify_ms, t.total_ms);
}

std::string TextureResultJson(const FeatureDbView& db, const texture::TextureResult& r,
                              int threads) {
  std::string json = "{\"frame\": \"camera\", \"objects\": [";
  char buffer[1024];
  for (size_t i = 0; i < r.objects.size(); ++i) {
    const texture::TextureObject& o = r.objects[i];
    json += i ? ", {" : "{";
    json += PoseJsonFields(db.model(o.model).name, o.cam_T_model);
    std::snprintf(buffer, sizeof(buffer),
                  ", \"verify\": [%.4f, %.4f], \"faces\": %u, \"feature_matches\": %u, "
                  "\"stereo_points\": %u, \"plane_mean_mm\": %.3f}",
                  o.print.zncc[0], o.print.zncc[1], o.faces, o.feature_matches, o.stereo_points,
                  o.plane_mean_mm);
    json += buffer;
  }
  const texture::TextureStats& s = r.stats;
  const texture::TextureTimings& t = r.time;
  std::snprintf(buffer, sizeof(buffer),
                "], \"texture\": {\"keypoints\": %u, \"matches\": %u, \"clusters\": %u, "
                "\"faces_2d\": %u, \"faces_3d\": %u, \"hypotheses\": %u, \"rejected\": %u}, "
                "\"time_ms\": {\"features\": %.3f, \"matching\": %.3f, \"clustering\": %.3f, "
                "\"stereo\": %.3f, \"verify\": %.3f, \"total\": %.3f}, \"threads\": %d}\n",
                s.keypoints, s.matches, s.clusters, s.faces_2d, s.faces_3d, s.hypotheses,
                s.rejected, t.features_ms, t.matching_ms, t.clustering_ms, t.stereo_ms, t.verify_ms,
                t.total_ms, threads);
  json += buffer;
  return json;
}

int RecognizePrinted(const StereoCalibration& calib, const FeatureDbView& db, ConstGrayView left,
                     ConstGrayView right, const TextureRun& run) {
  WorkerPool pool;
  Status s = pool.Start(run.threads);
  if (!s.ok()) return Fail("%s", s.message());
  texture::ParallelFor parallel;
  if (pool.threads() > 1) parallel = texture::ParallelOn(&pool);
  auto recognizer = MakeZeroed<texture::TextureRecognizer>();  // ~63 MiB, resident as used
  s = recognizer->Init(calib, db, texture::TextureRecognizerConfig{}, NowNs, parallel);
  if (!s.ok()) return Fail("%s", s.message());
  auto result = std::make_unique<texture::TextureResult>();
  s = recognizer->Process(left, right, result.get());
  if (!s.ok()) return Fail("%s", s.message());
  PrintTextureObjects(db, *result);
  if (run.json_path != nullptr &&
      !WriteTextFile(run.json_path, TextureResultJson(db, *result, pool.threads()))) {
    return Fail("cannot write %s: %s", run.json_path, std::strerror(errno));
  }
  if (run.overlay_path != nullptr) {
    PosedModel posed[texture::kMaxTextureObjects];
    for (size_t i = 0; i < result->objects.size(); ++i) {
      posed[i] = {&db.model(result->objects[i].model), result->objects[i].cam_T_model};
    }
    std::vector<uint8_t> rgb;
    int w = 0, h = 0;
    s = BuildPosedOverlay(calib, posed, result->objects.size(), left, right, &rgb, &w, &h);
    if (s.ok()) s = hal::WritePngRgb(run.overlay_path, rgb.data(), w, h, 3 * w);
    if (!s.ok()) return Fail("overlay %s: %s", run.overlay_path, s.message());
  }
  return 0;
}

}  // namespace sh::tools
