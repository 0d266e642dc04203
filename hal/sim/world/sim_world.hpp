// The simulator's world as the firmware sees it: reproducible scenes of the reference objects
// (and, with a folder of printed models, of printed cartons drawn with their artwork),
// rendered at boot (or at the first clear-fault that finds the model folder) into buffers owned
// here and played to the SimCamera as frames (frame n shows scene n mod scene_count), with the
// ground truth kept per scene. Rendering in advance keeps the trigger path free of allocation and
// of the renderer's cost.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "hal/sim/sim_camera_source.hpp"
#include "hal/sim/world/printed_surface.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "tables/textured_model.hpp"

namespace sh::render {

inline constexpr int kMaxSimScenes = 64;
// The plain models of a folder and the printed models of another (GenerateScene's limit).
inline constexpr int kMaxWorldModels = 64;

struct SimWorldConfig {
  const char* models_dir = "";
  // Folder of printed models (OBJ + MTL + artwork, hal/sim/textured_model_files) placed in the
  // scenes beside the plain ones, or "" for none. They follow the plain models in models().
  const char* printed_dir = "";
  uint64_t seed = 1;
  int scenes = 6;
  int objects = 3;
  bool light_background = false;
};

class SimWorld final : public hal::FrameSource {
 public:
  // Keeps the configuration; nothing is built yet.
  void Configure(const SimWorldConfig& config);
  // Loads the models, generates and renders every scene (allocates: boot, and a clear-fault
  // after a failed build) unless that has been done. A failure (a missing model folder) is
  // kept and tried again at the next call, so a folder repaired on the machine is picked up
  // without a restart. All scenes share one stereo rig and one table pose (a fixed camera).
  Status EnsureBuilt();
  Status Build(const SimWorldConfig& config) {
    Configure(config);
    return EnsureBuilt();
  }
  bool built() const { return n_scenes_ > 0; }

  // FrameSource: builds the world if needed (SimCamera::Start), then the frame size.
  Status Open(int* width, int* height) override;
  // Copies the pre-rendered images of scene frame_index mod scene_count().
  Status Render(uint64_t frame_index, GrayView left, GrayView right) override;

  // The rig of the rendered scenes: builds the world if needed, refuses while it cannot be.
  Result<StereoCalibration> Calibration();

  // Built worlds only (built() true).
  const StereoCalibration& calibration() const { return scenes_[0].calib; }
  // The rendered table (conveyor) frame in the left camera; identity until the world is built,
  // then the rig's. The address stays the same, so it can be read at recognition init.
  const RigidTransform& left_T_table() const { return left_T_table_; }
  int scene_count() const { return n_scenes_; }
  int SceneOfFrame(uint64_t frame_index) const {
    return static_cast<int>(frame_index % static_cast<uint64_t>(n_scenes_));
  }
  const GeneratedScene& scene(int i) const { return scenes_[i]; }
  // The models of the folder in its order (tables/model_files.hpp): scene objects index them.
  // Then the printed models of printed_dir, in file-name order.
  const Model* models() const { return models_.data(); }
  int model_count() const { return int(models_.size()); }
  bool is_printed(int model) const { return model >= n_plain_; }
  uint64_t seed() const { return config_.seed; }

 private:
  Status BuildNow();

  SimWorldConfig config_;
  std::vector<Model> models_;
  int n_plain_ = 0;
  std::vector<TexturedModel> printed_;
  std::vector<PrintedSurface> prints_;  // one per printed model, pointing into printed_
  std::unique_ptr<GeneratedScene[]> scenes_;
  int n_scenes_ = 0;
  int width_ = 0, height_ = 0;
  std::unique_ptr<uint8_t[]> pixels_;  // scene i: left then right, width x height each
  RigidTransform left_T_table_;
};

}  // namespace sh::render
