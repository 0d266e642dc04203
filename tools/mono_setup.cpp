#include "tools/mono_setup.hpp"

#include "recog/verify/draw_edges.hpp"
#include "tools/overlay.hpp"

#include <Eigen/Geometry>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace sh::tools {

Status LoadAspects(const RecognizeOptions& options, LoadedAspects* out) {
  // --aspects, else the ASPECTS_2D section of the --tables model set, else the built-in table.
  const char* path = options.aspects_path;
  if (path == nullptr && options.tables_path != nullptr) {
    const Result<uint32_t> kinds = FileBlobKinds(options.tables_path);
    if (!kinds.ok()) return kinds.status().WithContext("tables");
    if ((*kinds & KindBit(SectionKind::kAspects2d)) != 0) path = options.tables_path;
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

bool ApplyMonoSetting(const char* setting, MonoPipelineConfig* c) {
  const char* eq = std::strchr(setting, '=');
  if (eq == nullptr) return false;
  const std::string name(setting, eq);
  const float v = static_cast<float>(std::atof(eq + 1));
  MonoConfig& m = c->mono;
  struct FloatSetting {
    const char* name;
    float* value;
  };
  const FloatSetting floats[] = {
      {"mono.vote_threshold", &m.vote_threshold},
      {"mono.sigma_point_px", &m.voter.sigma_point_px},
      {"mono.sigma_line_px", &m.voter.sigma_line_px},
      {"mono.line_angle_window_deg", &m.voter.line_angle_window_deg},
      {"mono.min_match_fraction", &m.min_match_fraction},
      {"mono.early_match_fraction", &m.early_match_fraction},
      {"mono.max_scale_error", &m.max_scale_error},
      {"mono.max_depth_error", &m.max_depth_error},
      {"mono.max_tilt_deg", &m.max_tilt_deg},
      {"mono.missing_edge_penalty", &m.missing_edge_penalty},
      {"mono.competing_overlap", &m.competing_overlap},
      {"mono.verify.min_fraction", &m.verify.min_fraction},
      {"mono.verify.max_distance_px", &m.verify.max_distance_px},
      {"mono.features.canny_sigma_px", &c->features.canny.sigma_px},
      {"mono.features.corner_threshold", &c->features.corners.threshold},
  };
  for (const FloatSetting& f : floats) {
    if (name == f.name) {
      *f.value = v;
      return true;
    }
  }
  if (name == "mono.hypotheses_per_basis") {
    m.hypotheses_per_basis = static_cast<int>(v);
  } else if (name == "mono.max_fruitless_bases") {
    m.max_fruitless_bases = static_cast<uint32_t>(v);
  } else if (name == "mono.competing_bases") {
    m.competing_bases = static_cast<int>(v);
  } else if (name == "mono.exclude_interpenetrating") {
    m.exclude_interpenetrating = v != 0.0f;
  } else if (name == "mono.displace_weaker") {
    m.displace_weaker = v != 0.0f;
  } else if (name == "mono.junction_corners") {
    m.junction_corners = v != 0.0f;
  } else if (name == "mono.features.adaptive") {
    c->features.adaptive = v != 0.0f;
  } else {
    return false;
  }
  return true;
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
