// Rendered stereo scenes with ground truth for the pipeline's tests and the `bench scenes`
// command: a rendered pair with its truth in table model ids, and the comparison of recognised
// poses with the truth.
#pragma once

#include <cstdint>
#include <vector>

#include "hal/sim/world/scene_generator.hpp"
#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "recog/model/model.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/table_view.hpp"
#include "tools/eval/synthetic_scene.hpp"

namespace sh {

struct RenderModels {
  std::vector<Model> world;  // the model folder, in its order (tables/model_files.hpp)
  std::vector<Model> table;  // the table's models, with symmetry groups (for MatchToTruth)
};

// Loads the model folder `dir` for the renderer and the table's models for scoring. Truth
// objects carry table ids (by name): a rendered model the table lacks is clutter.
Status LoadRenderModels(const char* dir, const TableView& table, RenderModels* out);

struct RenderedPair {
  render::GeneratedScene generated;
  std::vector<uint8_t> left, right;  // packed grey images of the calibration's size
  std::vector<TruthObject> truth;    // model = table index, pose in the left camera frame
  ConstGrayView left_view() const;
  ConstGrayView right_view() const;
};

// Generates scene `seed` with `params` and renders both cameras.
Status RenderPair(uint64_t seed, const render::ScenarioParams& params, const RenderModels& models,
                  RenderedPair* out);

std::vector<RecognizedPose> PosesOf(const PipelineResult& result);

// Fraction of each scene object's silhouette that one camera sees (not hidden by the others):
// rays through every second pixel against the whole scene and against the object alone. An
// object outside the view counts as fully visible.
std::vector<float> VisibleFractions(const render::RenderScene& scene,
                                    const std::vector<Model>& models, const CameraIntrinsics& cam,
                                    const RigidTransform& cam_T_table);

}  // namespace sh
