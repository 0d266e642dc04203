#include "tools/mono_setup.hpp"

#include "recog/verify/draw_edges.hpp"
#include "recog/verify/view_camera.hpp"
#include "tools/overlay.hpp"
#include "tools/setting_table.hpp"

#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace sh::tools {

Status LoadAspects(const RecognizeOptions& options, LoadedAspects* out, bool required) {
  // --aspects, else the ASPECTS_2D section of the --tables model set, else the built-in table.
  const char* path = options.aspects_path;
  if (path == nullptr && options.tables_path != nullptr) {
    const Result<uint32_t> kinds = FileBlobKinds(options.tables_path);
    if (!kinds.ok()) return kinds.status().WithContext("tables");
    if ((*kinds & KindBit(SectionKind::kAspects2d)) != 0) {
      path = options.tables_path;
    } else if (required) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "--tables %s holds no aspect table, which one camera needs (build "
                           "one with tables build --hash-2d similarity)",
                           options.tables_path);
    }
  }
  if (path != nullptr) {
    const Status s = out->mapped.Open(path);
    if (!s.ok()) return s;
    out->view = out->mapped.view();
    return Status::Ok();
  }
  const Result<AspectTableView> builtin = OpenDefaultAspectTable();
  if (!builtin.ok()) {
    return Status::Error(builtin.status().code(), "built-in aspect table: %s",
                         builtin.status().message());
  }
  out->view = *builtin;
  return Status::Ok();
}

MonoPipelineConfig MakeMonoConfig(const RecognizeOptions& options) {
  if (options.background == nullptr) return MonoPipelineConfig::Automatic();
  return options.background[0] == 'l' ? MonoPipelineConfig::LightBackground()
                                      : MonoPipelineConfig::DarkBackground();
}

namespace {

// The monocular recogniser's settings worth exploring from the bench commands (`--set mono.*`).
constexpr Setting<MonoPipelineConfig> kMonoSettings[] = {
    {"mono.vote_threshold", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.vote_threshold = v; }},
    {"mono.sigma_point_px", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.voter.sigma_point_px = v; }},
    {"mono.sigma_line_px", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.voter.sigma_line_px = v; }},
    {"mono.line_angle_window_deg", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.voter.line_angle_window_deg = v; }},
    {"mono.min_match_fraction", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.min_match_fraction = v; }},
    {"mono.early_match_fraction", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.early_match_fraction = v; }},
    {"mono.max_scale_error", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.max_scale_error = v; }},
    {"mono.max_depth_error", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.max_depth_error = v; }},
    {"mono.max_tilt_deg", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.max_tilt_deg = v; }},
    {"mono.missing_edge_penalty", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.missing_edge_penalty = v; }},
    {"mono.competing_overlap", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.competing_overlap = v; }},
    {"mono.verify.min_fraction", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.verify.min_fraction = v; }},
    {"mono.verify.max_distance_px", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.verify.max_distance_px = v; }},
    {"mono.min_corner_isotropy", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.mono.min_corner_isotropy = v; }},
    {"mono.features.canny_sigma_px", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.features.canny.sigma_px = v; }},
    {"mono.features.canny_texture_factor", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.features.canny.texture_factor = v; }},
    {"mono.features.edge_snr", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.features.edge_snr = v; }},
    {"mono.features.corner_threshold", SettingKind::kReal,
     [](float v, MonoPipelineConfig& c) { c.features.corners.threshold = v; }},
    {"mono.hypotheses_per_basis", SettingKind::kCount,
     [](float v, MonoPipelineConfig& c) { c.mono.hypotheses_per_basis = static_cast<int>(v); }},
    {"mono.max_fruitless_bases", SettingKind::kCount,
     [](float v, MonoPipelineConfig& c) { c.mono.max_fruitless_bases = static_cast<uint32_t>(v); }},
    {"mono.competing_bases", SettingKind::kCount,
     [](float v, MonoPipelineConfig& c) { c.mono.competing_bases = static_cast<int>(v); }},
    {"mono.exclude_interpenetrating", SettingKind::kFlag,
     [](float v, MonoPipelineConfig& c) { c.mono.exclude_interpenetrating = v != 0.0f; }},
    {"mono.displace_weaker", SettingKind::kFlag,
     [](float v, MonoPipelineConfig& c) { c.mono.displace_weaker = v != 0.0f; }},
    {"mono.junction_corners", SettingKind::kFlag,
     [](float v, MonoPipelineConfig& c) { c.mono.junction_corners = v != 0.0f; }},
    {"mono.features.adaptive", SettingKind::kFlag,
     [](float v, MonoPipelineConfig& c) { c.features.adaptive = v != 0.0f; }},
};

}  // namespace

Status ApplyMonoSetting(const char* setting, MonoPipelineConfig* config) {
  return ApplySetting(setting, kMonoSettings, config);
}

std::string MonoSettingNames(const char* indent, size_t width) {
  return SettingNames(kMonoSettings, indent, width);
}

void PrintMonoResult(const AspectTableView& aspects, const MonoResult& r, int camera) {
  std::printf("monocular (%s camera): %zu object%s recognised\n", camera == 0 ? "left" : "right",
              r.objects.size(), r.objects.size() == 1 ? "" : "s");
  if (!r.objects.empty()) {
    std::printf("  %-2s %-10s %28s %28s %6s %13s\n", "#", "model", "t (mm, left camera)",
                "rotation vector (deg)", "vote", "edges / feat");
  }
  for (size_t i = 0; i < r.objects.size(); ++i) {
    PrintObjectLine(i, aspects.model(r.objects[i].model).name, r.objects[i]);
  }
  std::printf("features: 2-D points %u (+%u at line junctions), 2-D lines %u\n", r.points2d,
              r.junction_corners, r.lines2d);
  std::printf("recognition: %u of %u scene bases tried, %u hypotheses, %u verified, %u accepted\n",
              r.stats.scene_bases_tried, r.stats.scene_bases_available, r.stats.hypotheses,
              r.stats.verifications, r.stats.accepted);
  std::printf("time: features %.1f ms, recognition %.1f ms, total %.1f ms%s\n", r.time.features_ms,
              r.time.recognition_ms, r.time.total_ms,
              r.stats.budget_exhausted ? " (budget exhausted)" : "");
}

std::string MonoResultJson(const AspectTableView& aspects, const MonoResult& r,
                           const TableChoice& table, int camera) {
  std::string json = "{\"frame\": \"camera\", \"mode\": \"monocular\", \"camera\": \"";
  json += camera == 0 ? "left" : "right";
  json += "\", \"objects\": [";
  char buffer[1024];
  for (size_t i = 0; i < r.objects.size(); ++i) {
    json += (i ? ", " : "") + ObjectJson(aspects.model(r.objects[i].model).name, r.objects[i]);
  }
  std::snprintf(buffer, sizeof(buffer),
                "], \"features\": {\"points2d\": %u, \"junction_corners\": %u, \"lines2d\": %u}, "
                "\"recognition\": {\"scene_bases_tried\": %u, \"hypotheses\": %u, "
                "\"verifications\": %u, \"budget_exhausted\": %s}, \"table\": ",
                r.points2d, r.junction_corners, r.lines2d, r.stats.scene_bases_tried,
                r.stats.hypotheses, r.stats.verifications,
                r.stats.budget_exhausted ? "true" : "false");
  json += buffer;
  json += table.present ? "{\"source\": \"file\"}" : "{\"source\": \"none\"}";
  std::snprintf(buffer, sizeof(buffer),
                ", \"time_ms\": {\"features\": %.3f, \"recognition\": %.3f, \"total\": %.3f}}\n",
                r.time.features_ms, r.time.recognition_ms, r.time.total_ms);
  json += buffer;
  return json;
}

Status BuildMonoOverlay(const MonoPipeline& pipeline, const AspectTableView& aspects,
                        const MonoResult& result, ConstGrayView image, std::vector<uint8_t>* rgb,
                        int* width, int* height) {
  if (image.empty()) return Status::Error(StatusCode::kInvalidArgument, "overlay: no image");
  const int w = image.width, h = image.height;
  *width = w;
  *height = h;
  rgb->assign(size_t(w) * h * 3, 0);
  const ImageView<Rgb8> view{reinterpret_cast<Rgb8*>(rgb->data()), w, h, w};
  // The image dimmed a little so that the coloured edges stand out.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const uint8_t g = static_cast<uint8_t>(image.at(x, y) * 3 / 4);
      view.at(x, y) = {g, g, g};
    }
  }
  const size_t n = result.objects.size();
  PosedModel posed[kMaxObjects];
  for (size_t i = 0; i < n; ++i) {
    posed[i] = {&aspects.model(result.objects[i].model), result.objects[i].cam_T_model};
  }
  const ViewCamera& camera = pipeline.view();
  for (size_t i = 0; i < n; ++i) {
    // Every other recognised object may hide this one (at most kMaxOccluders of them).
    PosedModel occluders[kMaxOccluders];
    size_t n_occluders = 0;
    for (size_t k = 0; k < n && n_occluders < kMaxOccluders; ++k) {
      if (k != i) occluders[n_occluders++] = posed[k];
    }
    const Rgb8 colour = ObjectColour(static_cast<int>(i));
    SH_RETURN_IF_ERROR(DrawPosedModel(camera, posed[i], occluders, n_occluders, view, colour));
    const Eigen::Vector3f centre =
        camera.cam_T_left * (posed[i].cam_T_model * ModelCentroid(*posed[i].model));
    Eigen::Vector2d px;
    if (!ProjectToPixel(camera.intrinsics, centre.cast<double>(), &px)) continue;
    const char* name = posed[i].model->name;
    const int scale = 2;
    DrawText(view, static_cast<int>(px.x()) - TextWidth(name, scale) / 2,
             static_cast<int>(px.y()) - 7 * scale / 2, name, scale, colour);
  }
  return Status::Ok();
}

}  // namespace sh::tools
