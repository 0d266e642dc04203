// The simulator's world: reproducible scenes of the reference objects, rendered once at boot
// into buffers owned here and played to the SimCamera as frames (frame n shows scene
// n mod scene_count), with the ground truth kept per scene. Rendering in advance keeps the
// trigger path free of allocation and of the renderer's cost.
#pragma once

#include <cstdint>
#include <memory>

#include "firmware/recognition.hpp"
#include "hal/sim/render/model_directory.hpp"
#include "hal/sim/render/scene_generator.hpp"
#include "hal/sim/sim_camera_source.hpp"

namespace sh::fw {

inline constexpr int kMaxSimScenes = 64;

struct SimWorldConfig {
  const char* models_dir = "";
  uint64_t seed = 1;
  int scenes = 6;
  int objects = 3;
  bool light_background = false;
};

class SimWorld final : public hal::FrameSource {
 public:
  // Loads the models, generates and renders every scene (allocates; boot only). All scenes share
  // one stereo rig, whose calibration is calibration().
  Status Build(const SimWorldConfig& config);

  Status Open(int* width, int* height) override;
  // Copies the pre-rendered images of scene frame_index mod scene_count().
  Status Render(uint64_t frame_index, GrayView left, GrayView right) override;

  const StereoCalibration& calibration() const { return scenes_[0].calib; }
  int scene_count() const { return n_scenes_; }
  int SceneOfFrame(uint64_t frame_index) const {
    return static_cast<int>(frame_index % static_cast<uint64_t>(n_scenes_));
  }
  const render::GeneratedScene& scene(int i) const { return scenes_[i]; }
  const Model* models() const { return models_.get(); }
  int model_count() const { return n_models_; }
  uint64_t seed() const { return config_.seed; }

 private:
  SimWorldConfig config_;
  std::unique_ptr<Model[]> models_;
  int n_models_ = 0;
  std::unique_ptr<render::GeneratedScene[]> scenes_;
  int n_scenes_ = 0;
  int width_ = 0, height_ = 0;
  std::unique_ptr<uint8_t[]> pixels_;  // scene i: left then right, width x height each
};

// Simulator-only recognition that reports the rendered ground truth of the captured frame: it
// exercises capture, CAN publication and timing without depending on recognition quality.
class TruthRecognition final : public Recognition {
 public:
  explicit TruthRecognition(const SimWorld* world) : world_(world) {}
  Status Init(const StereoCalibration& calib, const TableView& table, uint32_t model_mask) override;
  Status SetModelMask(uint32_t model_mask) override {
    mask_ = model_mask;
    return Status::Ok();
  }
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;

 private:
  const SimWorld* world_;
  uint32_t mask_ = 0;
  int table_id_of_render_model_[render::kMaxModelFiles] = {};
};

// Table model id of each render model, by name (-1 when the table lacks it).
void MapRenderModelsToTable(const SimWorld& world, const TableView& table, int* ids);

}  // namespace sh::fw
