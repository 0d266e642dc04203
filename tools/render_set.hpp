// `stereohash render --scenes-per-row N`: a whole set of our renderer's scenes written in the
// recorded sets' layout (../shared/scenes/README.md), so that `stereohash bench recorded` scores
// our own scenes exactly as it scores the independent ray tracer's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hal/sim/world/model_colours.hpp"
#include "hal/sim/world/scene_generator.hpp"
#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh::tools {

// The models a rendered world is made of, with their colours: a model folder's (OBJ), or, with
// `tables_path`, the polyhedra of a model set's hash tables as they were built (CAD exports
// included: their units and origins applied), all grey.
Status LoadWorldModels(const std::string& models_dir, const std::string& tables_path,
                       std::vector<Model>* models, std::vector<render::ModelColour>* colours);

struct RenderSetOptions {
  std::string out_dir;
  std::string models_dir;
  std::string tables_path;        // the models of this model set instead of models_dir
  uint64_t seed = 1;              // scene k of the set uses seed + k
  int per_row = 2;                // scenes per background x occlusion row (6 rows)
  int objects = 0;                // per scene; 0: 4 and 5 alternately
  render::ScenarioParams params;  // camera, distance, baseline, noise (rows set the rest)
};

// Writes DIR/calib.yaml, DIR/table.yaml (one fixed rig over one table: the first scene's tilt),
// DIR/scenes.json and DIR/sceneNN/{left.png, right.png, truth.json} with the visible fraction
// of every object in each image. Images are colour (RGB PNG) when the folder holds colour parts
// (MTL Kd), grey otherwise. Prints one line per scene.
Status RenderRecordedSet(const RenderSetOptions& options);

}  // namespace sh::tools
