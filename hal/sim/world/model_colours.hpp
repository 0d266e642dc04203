// The diffuse colours of a model folder's single-colour parts (MTL Kd) for the renderer: which
// models are coloured, and the scene objects painted with them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hal/sim/world/render_scene.hpp"
#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh::render {

struct ModelColour {
  bool coloured = false;                         // the OBJ names a material with a Kd
  Eigen::Vector3f kd = Eigen::Vector3f::Ones();  // linear R, G, B in [0, 1]
};

// One entry per model of `models` (loaded from `dir`, model i from `<dir>/<name>.obj`): its MTL
// Kd, or not coloured when the OBJ names no material or its library cannot be read (as
// `tables build` treats it). A malformed library or several materials is an error naming the
// file.
Status LoadModelColours(const std::string& dir, const std::vector<Model>& models,
                        std::vector<ModelColour>* colours);

bool AnyColoured(const std::vector<ModelColour>& colours);

// Gives each object of a coloured model its colour, with albedo 1 (the Kd is the reflectance).
void PaintColourParts(const std::vector<ModelColour>& colours, RenderScene* scene);

}  // namespace sh::render
