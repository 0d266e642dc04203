#include "tools/render_set.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "hal/sim/world/model_colours.hpp"
#include "hal/sim/world/renderer.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tables/model_files.hpp"
#include "tables/table_file.hpp"
#include "tools/eval/rendered_eval.hpp"
#include "tools/report_util.hpp"

namespace sh::tools {
namespace {

struct RowSpec {
  render::Background background;
  render::Occlusion occlusion;
  const char *background_name, *occlusion_name;
};

// The thesis's experiment grid (table 5.4), in the recorded sets' order.
constexpr RowSpec kRows[] = {
    {render::Background::kDark, render::Occlusion::kNone, "dark", "none"},
    {render::Background::kDark, render::Occlusion::kSome, "dark", "some"},
    {render::Background::kDark, render::Occlusion::kSevere, "dark", "severe"},
    {render::Background::kLight, render::Occlusion::kNone, "light", "none"},
    {render::Background::kLight, render::Occlusion::kSome, "light", "some"},
    {render::Background::kLight, render::Occlusion::kSevere, "light", "severe"}};

Status MakeDir(const std::string& dir) {
  if (mkdir(dir.c_str(), 0777) != 0 && errno != EEXIST) {
    return Status::Error(StatusCode::kNotFound, "cannot create %s", dir.c_str());
  }
  return Status::Ok();
}

Status WriteText(const std::string& path, const std::string& text) {
  if (!WriteTextFile(path.c_str(), text)) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s", path.c_str());
  }
  return Status::Ok();
}

std::string TruthJson(const RowSpec& row, const render::GeneratedScene& g,
                      const std::vector<Model>& models, const std::vector<float>& vis_left,
                      const std::vector<float>& vis_right) {
  std::string json = std::string("{\"background\": \"") + row.background_name +
                     "\", \"occlusion\": \"" + row.occlusion_name + "\", \"objects\": [";
  for (size_t i = 0; i < g.scene.objects.size(); ++i) {
    const RigidTransform& T = g.left_T_model[i];
    const Model& model = models[g.scene.objects[i].model_index];
    char name[kJsonNameBytes];
    char b[640 + kJsonNameBytes];
    std::snprintf(b, sizeof(b),
                  "%s\n  {\"model\": \"%s\", \"R\": [[%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f], "
                  "[%.9f, %.9f, %.9f]], \"t\": [%.6f, %.6f, %.6f], \"visible\": [%.3f, %.3f]}",
                  i > 0 ? "," : "", JsonEscaped(model.name, sizeof(model.name), name, sizeof(name)),
                  T.R(0, 0), T.R(0, 1), T.R(0, 2), T.R(1, 0), T.R(1, 1), T.R(1, 2), T.R(2, 0),
                  T.R(2, 1), T.R(2, 2), T.t_mm.x(), T.t_mm.y(), T.t_mm.z(), vis_left[i],
                  vis_right[i]);
    json += b;
  }
  return json + "\n]}\n";
}

}  // namespace

Status LoadWorldModels(const std::string& models_dir, const std::string& tables_path,
                       std::vector<Model>* models, std::vector<render::ModelColour>* colours) {
  if (tables_path.empty()) {
    SH_RETURN_IF_ERROR(LoadModelFolder(models_dir, models));
    return render::LoadModelColours(models_dir, *models, colours);
  }
  MappedTable table;
  const Status opened = table.Open(tables_path.c_str());
  if (!opened.ok()) return opened.WithContext("--tables %s", tables_path.c_str());
  models->clear();
  for (uint32_t i = 0; i < table.view().model_count(); ++i) {
    models->push_back(table.view().model(i));
  }
  colours->assign(models->size(), render::ModelColour{});
  return Status::Ok();
}

Status RenderRecordedSet(const RenderSetOptions& options) {
  if (options.per_row < 1 || options.per_row > 100) {
    return Status::Error(StatusCode::kOutOfRange, "scenes per row %d outside 1..100",
                         options.per_row);
  }
  std::vector<Model> models;
  std::vector<render::ModelColour> colours;
  SH_RETURN_IF_ERROR(LoadWorldModels(options.models_dir, options.tables_path, &models, &colours));
  const bool colour = render::AnyColoured(colours);
  SH_RETURN_IF_ERROR(MakeDir(options.out_dir));

  render::ScenarioParams params = options.params;
  uint64_t seed = options.seed;
  StereoCalibration calib;
  RigidTransform left_T_table;
  std::string index = "{\"kind\": \"";
  index += colour ? "colour" : "polyhedra";
  index += "\", \"models\": \"" + options.models_dir +
           "\", \"seed\": " + std::to_string(options.seed) + ", \"scenes\": [";
  int scene_number = 0;
  for (const RowSpec& row : kRows) {
    for (int i = 0; i < options.per_row; ++i, ++scene_number) {
      params.background = row.background;
      params.occlusion = row.occlusion;
      params.n_objects = options.objects > 0 ? options.objects : 4 + (i % 2);
      // Some seeds cannot place the objects in view; the next seeds are tried (deterministic).
      Result<render::GeneratedScene> g =
          render::GenerateScene(seed++, params, models.data(), int(models.size()));
      for (int attempt = 0; !g.ok() && attempt < 16; ++attempt) {
        g = render::GenerateScene(seed++, params, models.data(), int(models.size()));
      }
      if (!g.ok()) return g.status().WithContext("scene %d", scene_number);
      // One rig bolted over one table: every later scene is seen from the first one's tilt.
      if (scene_number == 0) {
        params.tilt_deg = g->tilt_deg;
        calib = g->calib;
        left_T_table = g->scene.left_T_table;
      }
      g->calib = calib;
      render::PaintColourParts(colours, &g->scene);

      char name[16];
      std::snprintf(name, sizeof(name), "scene%02d", scene_number);
      const std::string dir = options.out_dir + "/" + name;
      SH_RETURN_IF_ERROR(MakeDir(dir));
      const int w = calib.left.width, h = calib.left.height;
      const size_t n = size_t(w) * size_t(h);
      std::vector<uint8_t> grey[2];
      std::vector<Rgb8> rgb[2];
      render::RenderTargets targets[2];
      for (int k = 0; k < 2; ++k) {
        if (colour) {
          rgb[k].resize(n);
          targets[k].rgb = {rgb[k].data(), w, h, w};
        } else {
          grey[k].resize(n);
          targets[k].image = {grey[k].data(), w, h, w};
        }
      }
      SH_RETURN_IF_ERROR(render::RenderStereo(g->scene, models.data(), int(models.size()), calib,
                                              targets[0], targets[1]));
      const char* files[2] = {"/left.png", "/right.png"};
      for (int k = 0; k < 2; ++k) {
        const std::string path = dir + files[k];
        SH_RETURN_IF_ERROR(
            colour ? hal::WritePngRgb(path.c_str(), reinterpret_cast<const uint8_t*>(rgb[k].data()),
                                      w, h, 3 * w)
                   : hal::WritePng(path.c_str(), ConstGrayView{grey[k].data(), w, h, w}));
      }
      const std::vector<float> vis_left =
          VisibleFractions(g->scene, models, calib.left, g->scene.left_T_table);
      const std::vector<float> vis_right =
          VisibleFractions(g->scene, models, calib.right, render::RightFromTable(g->scene, calib));
      SH_RETURN_IF_ERROR(
          WriteText(dir + "/truth.json", TruthJson(row, *g, models, vis_left, vis_right)));
      char entry[192];
      std::snprintf(entry, sizeof(entry),
                    "%s\n {\"scene\": \"%s\", \"background\": \"%s\", \"occlusion\": \"%s\", "
                    "\"objects\": %zu, \"seed\": %llu}",
                    scene_number > 0 ? "," : "", name, row.background_name, row.occlusion_name,
                    g->scene.objects.size(), static_cast<unsigned long long>(seed - 1));
      index += entry;
      std::printf("%s: %s table, %s occlusion, %zu objects (seed %llu)\n", name,
                  row.background_name, row.occlusion_name, g->scene.objects.size(),
                  static_cast<unsigned long long>(seed - 1));
    }
  }
  std::vector<char> yaml(8192);
  const Result<size_t> calib_size = WriteCalibrationYaml(calib, yaml.data(), yaml.size());
  if (!calib_size.ok()) return calib_size.status();
  SH_RETURN_IF_ERROR(
      WriteText(options.out_dir + "/calib.yaml", std::string(yaml.data(), *calib_size)));
  const Result<size_t> table_size = WriteTableYaml(left_T_table, yaml.data(), yaml.size());
  if (!table_size.ok()) return table_size.status();
  SH_RETURN_IF_ERROR(
      WriteText(options.out_dir + "/table.yaml", std::string(yaml.data(), *table_size)));
  return WriteText(options.out_dir + "/scenes.json", index + "\n]}\n");
}

}  // namespace sh::tools
