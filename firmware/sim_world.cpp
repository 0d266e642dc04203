#include "firmware/sim_world.hpp"

#include <cstring>

#include "hal/sim/render/renderer.hpp"

namespace sh::fw {

Status SimWorld::Build(const SimWorldConfig& config) {
  if (config.scenes < 1 || config.scenes > kMaxSimScenes) {
    return Status::Error(StatusCode::kOutOfRange, "sim scenes %d outside 1..%d", config.scenes,
                         kMaxSimScenes);
  }
  config_ = config;
  models_.reset(new Model[render::kMaxModelFiles]);
  const Result<int> n =
      render::LoadModelDirectory(config.models_dir, models_.get(), render::kMaxModelFiles);
  if (!n.ok()) return n.status();
  if (*n == 0) {
    return Status::Error(StatusCode::kNotFound, "no .obj models in %s", config.models_dir);
  }
  n_models_ = *n;
  render::ScenarioParams params;
  params.n_objects = config.objects;
  params.background =
      config.light_background ? render::Background::kLight : render::Background::kDark;
  scenes_.reset(new render::GeneratedScene[config.scenes]);
  uint64_t seed = config.seed;
  for (int i = 0; i < config.scenes; ++i) {
    // Some seeds cannot place the objects in view; the next seeds are tried (deterministic).
    Result<render::GeneratedScene> g =
        render::GenerateScene(seed++, params, models_.get(), n_models_);
    for (int attempt = 0; !g.ok() && attempt < 16; ++attempt) {
      g = render::GenerateScene(seed++, params, models_.get(), n_models_);
    }
    if (!g.ok()) {
      return Status::Error(g.status().code(), "sim scene %d (seed %llu): %s", i,
                           static_cast<unsigned long long>(seed - 1), g.status().message());
    }
    scenes_[i] = *g;
    const StereoCalibration& c0 = scenes_[0].calib;
    const StereoCalibration& ci = scenes_[i].calib;
    if (ci.left.width != c0.left.width || ci.left.height != c0.left.height ||
        !ci.right_R_left.isApprox(c0.right_R_left, 1e-4) ||
        !ci.right_t_left_mm.isApprox(c0.right_t_left_mm, 1e-4)) {
      return Status::Error(StatusCode::kInternal, "sim scene %d uses a different rig", i);
    }
    // One calibration for every scene (the rigs agree up to float rounding).
    scenes_[i].calib = c0;
  }
  n_scenes_ = config.scenes;
  width_ = scenes_[0].calib.left.width;
  height_ = scenes_[0].calib.left.height;
  const size_t per_image = size_t(width_) * size_t(height_);
  pixels_.reset(new uint8_t[per_image * 2 * size_t(n_scenes_)]);
  for (int i = 0; i < n_scenes_; ++i) {
    uint8_t* left = pixels_.get() + per_image * 2 * size_t(i);
    GrayView l{left, width_, height_, width_};
    GrayView r{left + per_image, width_, height_, width_};
    SH_RETURN_IF_ERROR(
        render::RenderStereo(scenes_[i].scene, models_.get(), n_models_, scenes_[i].calib, l, r));
  }
  return Status::Ok();
}

Status SimWorld::Open(int* width, int* height) {
  if (n_scenes_ == 0) {
    return Status::Error(StatusCode::kFailedPrecondition, "sim world not built");
  }
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

void MapRenderModelsToTable(const SimWorld& world, const TableView& table, int* ids) {
  for (int m = 0; m < world.model_count(); ++m) ids[m] = table.FindModel(world.models()[m].name);
}

Status TruthRecognition::Init(const StereoCalibration& calib, const TableView& table,
                              uint32_t model_mask) {
  mask_ = model_mask;
  MapRenderModelsToTable(*world_, table, table_id_of_render_model_);
  return Status::Ok();
}

Status TruthRecognition::Process(const hal::StereoFrame& frame, float budget_ms,
                                 protocol::ResultSet* set) {
  const render::GeneratedScene& g = world_->scene(world_->SceneOfFrame(frame.left_sequence));
  uint8_t instances[32] = {};
  size_t n = 0;
  for (size_t i = 0; i < g.scene.objects.size() && n < protocol::kMaxResultObjects; ++i) {
    const int id = table_id_of_render_model_[g.scene.objects[i].model_index];
    if (id < 0 || id > 31 || !(mask_ & (1u << id))) continue;
    set->objects[n++] =
        protocol::MakeObjectPose(g.left_T_model[i], static_cast<uint8_t>(id), instances[id]++, 1.0);
  }
  set->object_count = static_cast<uint8_t>(n);
  set->status = protocol::ResultStatus::kOk;
  return Status::Ok();
}

}  // namespace sh::fw
