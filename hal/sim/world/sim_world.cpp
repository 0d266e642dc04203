#include "hal/sim/world/sim_world.hpp"

#include <cstring>

#include "hal/sim/textured_model_files.hpp"
#include "hal/sim/world/renderer.hpp"
#include "tables/model_files.hpp"

namespace sh::render {

void SimWorld::Configure(const SimWorldConfig& config) {
  config_ = config;
  n_scenes_ = 0;
}

Status SimWorld::EnsureBuilt() {
  if (built()) return Status::Ok();
  return BuildNow();  // sets n_scenes_ only when complete
}

Status SimWorld::BuildNow() {
  const SimWorldConfig& config = config_;
  if (config.scenes < 1 || config.scenes > kMaxSimScenes) {
    return Status::Error(StatusCode::kOutOfRange, "sim scenes %d outside 1..%d", config.scenes,
                         kMaxSimScenes);
  }
  SH_RETURN_IF_ERROR(LoadModelFolder(config.models_dir, &models_));
  n_plain_ = model_count();
  printed_.clear();
  if (config.printed_dir[0] != '\0') {
    std::vector<std::string> names;
    SH_RETURN_IF_ERROR(ModelFolderNames(config.printed_dir, &names));
    for (const std::string& name : names) {
      Result<TexturedModel> m =
          LoadTexturedModelFile(std::string(config.printed_dir) + "/" + name + ".obj");
      if (!m.ok()) return m.status();
      if (!m->texturing.textured()) {
        return Status::Error(StatusCode::kInvalidArgument, "%s/%s.obj has no printed face",
                             config.printed_dir, name.c_str());
      }
      models_.push_back(m->model);
      printed_.push_back(std::move(*m));
    }
    if (model_count() > kMaxWorldModels) {
      return Status::Error(StatusCode::kOutOfRange, "more than %d models in the sim world",
                           kMaxWorldModels);
    }
  }
  prints_.clear();
  prints_.reserve(printed_.size());
  for (const TexturedModel& t : printed_) prints_.push_back(PrintOf(t));
  ScenarioParams params;
  params.n_objects = config.objects;
  params.background = config.light_background ? Background::kLight : Background::kDark;
  scenes_.reset(new GeneratedScene[config.scenes]);
  uint64_t seed = config.seed;
  for (int i = 0; i < config.scenes; ++i) {
    // Some seeds cannot place the objects in view; the next seeds are tried (deterministic).
    Result<GeneratedScene> g = GenerateScene(seed++, params, models_.data(), model_count());
    for (int attempt = 0; !g.ok() && attempt < 16; ++attempt) {
      g = GenerateScene(seed++, params, models_.data(), model_count());
    }
    if (!g.ok()) {
      return g.status().WithContext("sim scene %d (seed %llu)", i,
                                    static_cast<unsigned long long>(seed - 1));
    }
    scenes_[i] = *g;
    // The cameras stay where they were bolted: every later scene is seen from scene 0's tilt, so
    // all scenes share one table pose (the firmware bounds and the one-camera fallback use it).
    if (i == 0) params.tilt_deg = g->tilt_deg;
    for (SceneObject& o : scenes_[i].scene.objects) {
      if (!is_printed(o.model_index)) continue;
      o.albedo = 0.95f;  // the print sets the reflectance
      o.print = &prints_[size_t(o.model_index - n_plain_)];
    }
    const StereoCalibration& c0 = scenes_[0].calib;
    const StereoCalibration& ci = scenes_[i].calib;
    if (ci.left.width != c0.left.width || ci.left.height != c0.left.height ||
        !ci.right_R_left.isApprox(c0.right_R_left, 1e-4) ||
        !ci.right_t_left_mm.isApprox(c0.right_t_left_mm, 1e-4) ||
        !scenes_[i].scene.left_T_table.R.isApprox(scenes_[0].scene.left_T_table.R, 1e-4)) {
      return Status::Error(StatusCode::kInternal, "sim scene %d uses a different rig", i);
    }
    // One calibration for every scene (the rigs agree up to float rounding).
    scenes_[i].calib = c0;
  }
  width_ = scenes_[0].calib.left.width;
  height_ = scenes_[0].calib.left.height;
  const size_t per_image = size_t(width_) * size_t(height_);
  pixels_.reset(new uint8_t[per_image * 2 * size_t(config.scenes)]);
  for (int i = 0; i < config.scenes; ++i) {
    uint8_t* left = pixels_.get() + per_image * 2 * size_t(i);
    GrayView l{left, width_, height_, width_};
    GrayView r{left + per_image, width_, height_, width_};
    SH_RETURN_IF_ERROR(
        RenderStereo(scenes_[i].scene, models_.data(), model_count(), scenes_[i].calib, l, r));
  }
  left_T_table_ = scenes_[0].scene.left_T_table;
  n_scenes_ = config.scenes;  // last: built() means complete
  return Status::Ok();
}

Result<StereoCalibration> SimWorld::Calibration() {
  SH_RETURN_IF_ERROR(
      EnsureBuilt().WithContext("the simulator's rig is unknown until its world is built"));
  return scenes_[0].calib;
}

Status SimWorld::Open(int* width, int* height) {
  SH_RETURN_IF_ERROR(EnsureBuilt().WithContext("simulator world"));
  *width = width_;
  *height = height_;
  return Status::Ok();
}

Status SimWorld::Render(uint64_t frame_index, GrayView left, GrayView right) {
  const size_t per_image = size_t(width_) * size_t(height_);
  const uint8_t* src = pixels_.get() + per_image * 2 * size_t(SceneOfFrame(frame_index));
  for (int y = 0; y < height_; ++y) {
    std::memcpy(left.row(y), src + size_t(y) * width_, size_t(width_));
    std::memcpy(right.row(y), src + per_image + size_t(y) * width_, size_t(width_));
  }
  return Status::Ok();
}

}  // namespace sh::render
