// Rendered stereo scenes with ground truth for the pipeline's tests and the `bench scenes`
// command: the renderer's models mapped onto the table's models by name, a rendered pair, and
// the comparison of recognised poses with the truth.
#pragma once

#include <cstdint>
#include <vector>

#include "hal/sim/render/scene_generator.hpp"
#include "recog/base/status.hpp"
#include "recog/image/image.hpp"
#include "recog/model/model.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/table_view.hpp"
#include "tests/support/synthetic_scene.hpp"

namespace sh::testing_support {

struct RenderModels {
  std::vector<Model> render;     // as loaded from the OBJ folder (renderer's indices)
  std::vector<int> table_index;  // render model i is table model table_index[i] (-1: absent)
  std::vector<Model> table;      // the table's models, with symmetry groups (for MatchToTruth)
};

// Loads every OBJ model of `dir` and maps it onto `table` by name.
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

}  // namespace sh::testing_support
