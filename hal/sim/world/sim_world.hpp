// The simulator's world as the firmware sees it: reproducible scenes of the reference objects
// (and, with a folder of printed models, of printed cartons drawn with their artwork; with a
// folder of colour parts, of those drawn in their MTL colour, delivered as NV12 frames),
// rendered at boot (or at the first clear-fault that finds the model folder) into buffers owned
// here and played to the SimCamera as frames (frame n shows scene n mod scene_count), with the
// ground truth kept per scene. Rendering in advance keeps the trigger path free of allocation and
// of the renderer's cost.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "hal/sim/sim_camera_source.hpp"
#include "hal/sim/world/model_colours.hpp"
#include "hal/sim/world/printed_surface.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "recog/model/textured_model.hpp"

namespace sh::render {

inline constexpr int kMaxSimScenes = 64;
// The plain models of a folder and the printed models of another (GenerateScene's limit).
inline constexpr int kMaxWorldModels = 64;

struct SimWorldConfig {
  const char* models_dir = "";
  // Folder of printed models (OBJ + MTL + artwork, hal/sim/textured_model_files) placed in the
  // scenes beside the plain ones, or "" for none. They follow the plain models in models().
  const char* printed_dir = "";
  // Folder of single-colour parts (OBJ + MTL with a Kd, e.g. models/colour) placed beside the
  // plain models and drawn in their colour, or "" for none. They follow the plain models in
  // models(). Models of models_dir with a Kd are drawn in their colour too.
  const char* colour_dir = "";
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
  // Copies the pre-rendered images of scene frame_index mod scene_count() (the Y planes of a
  // colour world).
  Status Render(uint64_t frame_index, GrayView left, GrayView right) override;
  // NV12 frames when the world holds colour parts (BT.601 full range, as a colour sensor's ISP
  // gives them); grey otherwise.
  FrameFormat format() const override { return colour_ ? FrameFormat::kNv12 : FrameFormat::kGray8; }
  Status RenderNv12(uint64_t frame_index, const hal::Nv12Target& left,
                    const hal::Nv12Target& right) override;
  bool colour() const { return colour_; }

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
  bool is_coloured(int model) const { return colours_[size_t(model)].coloured; }
  uint64_t seed() const { return config_.seed; }

 private:
  Status BuildNow();

  SimWorldConfig config_;
  std::vector<Model> models_;
  int n_plain_ = 0;  // the plain models and the colour parts, before the printed models
  std::vector<ModelColour> colours_;  // one per model
  bool colour_ = false;               // some model is coloured: frames are NV12
  std::vector<TexturedModel> printed_;
  std::vector<PrintedSurface> prints_;  // one per printed model, pointing into printed_
  std::unique_ptr<GeneratedScene[]> scenes_;
  int n_scenes_ = 0;
  int width_ = 0, height_ = 0;
  // Scene i: left then right, each width x height (grey) or the Y plane then the chroma pairs
  // (NV12, image_bytes_ in all).
  std::unique_ptr<uint8_t[]> pixels_;
  size_t image_bytes_ = 0;
  RigidTransform left_T_table_;
};

}  // namespace sh::render
