// `stereohash render`: writes a simulated stereo pair with its calibration and ground truth.
#include <sys/stat.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "hal/sim/image_files.hpp"
#include "hal/sim/world/model_colours.hpp"
#include "hal/sim/world/renderer.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "recog/base/printable.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tables/model_files.hpp"
#include "tools/command.hpp"
#include "tools/render_set.hpp"

namespace sh::tools {
namespace {

void PrintHelp() {
  std::printf(
      "usage: stereohash render --out DIR [--seed N] [--objects N] [--background dark|light]\n"
      "                         [--occlusion none|some|severe] [--distance-mm MM]\n"
      "                         [--baseline-mm MM] [--noise SIGMA] [--models DIR | --tables F]\n"
      "                         [--camera thesis|wide|tele|hd] [--scenes-per-row N]\n"
      "Renders reference objects lying on a table, seen by a calibrated stereo pair, and writes\n"
      "DIR/left.png, DIR/right.png, DIR/calib.yaml (OpenCV FileStorage: K1 D1 K2 D2 R T, mm),\n"
      "DIR/table.yaml (R_table, t_table: x_left = R_table x_table + t_table, table z up)\n"
      "and DIR/truth.json (per object: model name, R and t with x_left_cam = R x_model + t, mm).\n"
      "Colour parts (an OBJ whose material has an MTL Kd, e.g. models/colour) are drawn in their\n"
      "colour and the images are then RGB PNGs. --tables F renders the polyhedra of a model set\n"
      "as `tables build` made them (STL, PLY, 3MF parts included), in place of --models.\n"
      "--scenes-per-row N writes a recorded set instead (the layout of ../shared/scenes, scored\n"
      "by `stereohash bench recorded DIR`): N scenes per dark/light x none/some/severe row,\n"
      "seeds from --seed on, one rig over one table, 4 and 5 objects unless --objects.\n"
      "Defaults: --seed 1 --objects 4 --background dark --occlusion some --distance-mm 400\n"
      "          --baseline-mm 120 --noise 1.5 --models %s\n",
      STEREOHASH_DEFAULT_MODELS_DIR);
}

Status WriteText(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    return Status::Error(StatusCode::kNotFound, "cannot create %s: %s", path.c_str(),
                         std::strerror(errno));
  }
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) {
    return Status::Error(StatusCode::kUnavailable, "cannot write %s", path.c_str());
  }
  return Status::Ok();
}

std::string TruthJson(const render::GeneratedScene& g, const Model* models, uint64_t seed,
                      const render::ScenarioParams& p, const char* background,
                      const char* occlusion) {
  std::string json = "{\n  \"seed\": " + std::to_string(seed) + ",\n";
  char buffer[512 + kJsonNameBytes];
  std::snprintf(buffer, sizeof(buffer),
                "  \"background\": \"%s\",\n  \"occlusion\": \"%s\",\n"
                "  \"camera_distance_mm\": %.1f,\n  \"baseline_mm\": %.1f,\n"
                "  \"noise_sigma\": %.3f,\n  \"frame\": \"left camera, OpenCV axes, mm; "
                "x_cam = R x_model + t\",\n  \"objects\": [",
                background, occlusion, p.camera_distance_mm, p.baseline_mm, p.noise_sigma);
  json += buffer;
  for (size_t i = 0; i < g.scene.objects.size(); ++i) {
    const RigidTransform& T = g.left_T_model[i];
    const Model& model = models[g.scene.objects[i].model_index];
    char name[kJsonNameBytes];
    std::snprintf(buffer, sizeof(buffer),
                  "%s\n    {\"model\": \"%s\", \"R\": [[%.9f, %.9f, %.9f], [%.9f, %.9f, %.9f], "
                  "[%.9f, %.9f, %.9f]], \"t\": [%.6f, %.6f, %.6f], \"albedo\": %.3f}",
                  i ? "," : "", JsonEscaped(model.name, sizeof(model.name), name, sizeof(name)),
                  T.R(0, 0), T.R(0, 1), T.R(0, 2), T.R(1, 0), T.R(1, 1), T.R(1, 2), T.R(2, 0),
                  T.R(2, 1), T.R(2, 2), T.t_mm.x(), T.t_mm.y(), T.t_mm.z(),
                  g.scene.objects[i].albedo);
    json += buffer;
  }
  json += "\n  ]\n}\n";
  return json;
}

// The command line of `stereohash render`, with its defaults.
struct RenderArgs {
  const char* out_dir = nullptr;
  const char* models_dir = STEREOHASH_DEFAULT_MODELS_DIR;
  const char* tables_path = "";  // --tables: a model set's polyhedra instead
  const char* background = "dark";
  const char* occlusion = "some";
  uint64_t seed = 1;
  render::ScenarioParams params;
  int per_row = 0;      // --scenes-per-row: a recorded set
  int set_objects = 0;  // --objects given
};

// Reads the options into `args`; false (with the exit code) for --help or a bad option.
bool ParseRenderArgs(int argc, char** argv, RenderArgs* args, int* exit_code) {
  render::ScenarioParams& params = args->params;
  for (int i = 1; i < argc; ++i) {
    const char *arg = nullptr, *value = nullptr;
    if (!NextOption("render", argc, argv, PrintHelp, &i, &arg, &value, exit_code)) return false;
    double number = 0;
    // Within float's range here (the floats' own ranges are checked by GenerateScene); counts
    // and the seed must be whole numbers in their ranges below.
    const bool numeric = ParseNumber(value, -1e30, 1e30, &number);
    const bool whole = numeric && number == std::floor(number);
    if (std::strcmp(arg, "--out") == 0) {
      args->out_dir = value;
    } else if (std::strcmp(arg, "--models") == 0) {
      args->models_dir = value;
    } else if (std::strcmp(arg, "--tables") == 0) {
      args->tables_path = value;
    } else if (std::strcmp(arg, "--seed") == 0 && whole && number >= 0 && number < 1.8e19) {
      args->seed = static_cast<uint64_t>(number);
    } else if (std::strcmp(arg, "--objects") == 0 && whole && number >= 1 &&
               number <= render::kMaxRenderObjects) {
      params.n_objects = static_cast<int>(number);
      args->set_objects = params.n_objects;
    } else if (std::strcmp(arg, "--scenes-per-row") == 0 && whole && number >= 1 && number <= 100) {
      args->per_row = static_cast<int>(number);
    } else if (std::strcmp(arg, "--distance-mm") == 0 && numeric) {
      params.camera_distance_mm = static_cast<float>(number);
    } else if (std::strcmp(arg, "--baseline-mm") == 0 && numeric) {
      params.baseline_mm = static_cast<float>(number);
    } else if (std::strcmp(arg, "--camera") == 0 && render::NamedCamera(value, &params)) {
      // another camera than the thesis's (scene_generator.hpp)
    } else if (std::strcmp(arg, "--noise") == 0 && numeric) {
      params.noise_sigma = static_cast<float>(number);
    } else if (std::strcmp(arg, "--background") == 0 &&
               (std::strcmp(value, "dark") == 0 || std::strcmp(value, "light") == 0)) {
      args->background = value;
      params.background = value[0] == 'd' ? render::Background::kDark : render::Background::kLight;
    } else if (std::strcmp(arg, "--occlusion") == 0 &&
               (std::strcmp(value, "none") == 0 || std::strcmp(value, "some") == 0 ||
                std::strcmp(value, "severe") == 0)) {
      args->occlusion = value;
      params.occlusion = value[1] == 'o'   ? render::Occlusion::kNone
                         : value[1] == 'e' ? render::Occlusion::kSevere
                                           : render::Occlusion::kSome;
    } else {
      std::fprintf(stderr, "stereohash render: bad option or value: %s %s (see --help)\n", arg,
                   value);
      *exit_code = 2;
      return false;
    }
  }
  if (args->out_dir == nullptr) {
    std::fprintf(stderr, "stereohash render: --out DIR is required (see --help)\n");
    *exit_code = 2;
    return false;
  }
  return true;
}

// --scenes-per-row: the recorded set.
int RenderSet(const RenderArgs& args) {
  RenderSetOptions set;
  set.out_dir = args.out_dir;
  set.models_dir = args.models_dir;
  set.tables_path = args.tables_path;
  set.seed = args.seed;
  set.per_row = args.per_row;
  set.objects = args.set_objects;
  set.params = args.params;
  const Status written = RenderRecordedSet(set);
  if (!written.ok()) {
    std::fprintf(stderr, "stereohash render: %s\n", written.message());
    return 1;
  }
  std::printf("wrote %d scenes to %s\n", 6 * args.per_row, args.out_dir);
  return 0;
}

// A rendered stereo pair: grey images, or RGB ones when a colour part is in the scene.
struct RenderedImages {
  bool colour = false;
  int width = 0, height = 0;
  std::vector<uint8_t> left, right;
  std::vector<Rgb8> left_rgb, right_rgb;
  double render_ms = 0;
};

Status RenderImages(const render::GeneratedScene& scene, const std::vector<Model>& model_set,
                    bool colour, RenderedImages* images) {
  const CameraIntrinsics& cam = scene.calib.left;
  const size_t pixels = size_t(cam.width) * cam.height;
  images->colour = colour;
  images->width = cam.width;
  images->height = cam.height;
  images->left.resize(colour ? 0 : pixels);
  images->right.resize(images->left.size());
  images->left_rgb.resize(colour ? pixels : 0);
  images->right_rgb.resize(images->left_rgb.size());
  render::RenderTargets left_targets, right_targets;
  if (colour) {
    left_targets.rgb = {images->left_rgb.data(), cam.width, cam.height, cam.width};
    right_targets.rgb = {images->right_rgb.data(), cam.width, cam.height, cam.width};
  } else {
    left_targets.image = {images->left.data(), cam.width, cam.height, cam.width};
    right_targets.image = {images->right.data(), cam.width, cam.height, cam.width};
  }
  const auto start = std::chrono::steady_clock::now();
  const Status rendered = render::RenderStereo(scene.scene, model_set.data(), int(model_set.size()),
                                               scene.calib, left_targets, right_targets);
  images->render_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return rendered;
}

// DIR/{left.png,right.png,calib.yaml,table.yaml,truth.json} of a rendered scene.
Status WriteSceneFiles(const RenderArgs& args, const render::GeneratedScene& scene,
                       const std::vector<Model>& model_set, const RenderedImages& images) {
  const std::string dir(args.out_dir);
  std::vector<char> yaml(8192);
  const Result<size_t> yaml_size = WriteCalibrationYaml(scene.calib, yaml.data(), yaml.size());
  Status st = yaml_size.ok() ? Status::Ok() : yaml_size.status();
  for (int k = 0; k < 2 && st.ok(); ++k) {
    const std::string path = dir + (k == 0 ? "/left.png" : "/right.png");
    st = images.colour ? hal::WritePngRgb(path.c_str(),
                                          reinterpret_cast<const uint8_t*>(
                                              (k == 0 ? images.left_rgb : images.right_rgb).data()),
                                          images.width, images.height, 3 * images.width)
                       : hal::WritePng(path.c_str(),
                                       ConstGrayView{(k == 0 ? images.left : images.right).data(),
                                                     images.width, images.height, images.width});
  }
  if (st.ok()) st = WriteText(dir + "/calib.yaml", std::string(yaml.data(), *yaml_size));
  // The table's pose, as an installation measures it once (`recognize --table`).
  std::vector<char> table_yaml(4096);
  const Result<size_t> table_size =
      WriteTableYaml(scene.scene.left_T_table, table_yaml.data(), table_yaml.size());
  if (st.ok() && !table_size.ok()) st = table_size.status();
  if (st.ok()) st = WriteText(dir + "/table.yaml", std::string(table_yaml.data(), *table_size));
  if (st.ok()) {
    st = WriteText(dir + "/truth.json", TruthJson(scene, model_set.data(), args.seed, args.params,
                                                  args.background, args.occlusion));
  }
  return st;
}

// One scene: generated, rendered and written.
int RenderOneScene(const RenderArgs& args) {
  std::vector<Model> model_set;
  std::vector<render::ModelColour> colours;
  const Status loaded = LoadWorldModels(args.models_dir, args.tables_path, &model_set, &colours);
  if (!loaded.ok()) {
    std::fprintf(stderr, "stereohash render: %s\n", loaded.message());
    return 1;
  }
  Result<render::GeneratedScene> scene =
      render::GenerateScene(args.seed, args.params, model_set.data(), int(model_set.size()));
  if (!scene.ok()) {
    std::fprintf(stderr, "stereohash render: %s\n", scene.status().message());
    return 1;
  }
  render::PaintColourParts(colours, &scene->scene);
  RenderedImages images;
  const Status rendered = RenderImages(*scene, model_set, render::AnyColoured(colours), &images);
  if (!rendered.ok()) {
    std::fprintf(stderr, "stereohash render: %s\n", rendered.message());
    return 1;
  }
  if (mkdir(args.out_dir, 0777) != 0 && errno != EEXIST) {
    std::fprintf(stderr, "stereohash render: cannot create %s: %s\n", args.out_dir,
                 std::strerror(errno));
    return 1;
  }
  const Status st = WriteSceneFiles(args, *scene, model_set, images);
  if (!st.ok()) {
    std::fprintf(stderr, "stereohash render: %s\n", st.message());
    return 1;
  }
  std::printf(
      "rendered %zu objects (seed %llu) in %.0f ms -> %s/{left.png,right.png,calib.yaml,"
      "table.yaml,truth.json}\n",
      scene->scene.objects.size(), static_cast<unsigned long long>(args.seed), images.render_ms,
      args.out_dir);
  return 0;
}

int RunRender(int argc, char** argv) {
  RenderArgs args;
  int exit_code = 0;
  if (!ParseRenderArgs(argc, argv, &args, &exit_code)) return exit_code;
  return args.per_row > 0 ? RenderSet(args) : RenderOneScene(args);
}

}  // namespace

SH_REGISTER_COMMAND(render, "render a simulated stereo pair with calibration and ground truth",
                    RunRender);

}  // namespace sh::tools
