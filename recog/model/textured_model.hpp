// A printed (textured) model in memory: the polyhedron, its faces' UV maps and materials, and
// the grey texture images the database builder learns from (host only; never per frame).
#pragma once

#include <cstdint>
#include <vector>

#include "recog/image/image.hpp"
#include "recog/model/model.hpp"
#include "recog/model/obj_texture.hpp"

namespace sh {

struct GreyImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;  // row-major, stride = width
  ConstGrayView view() const { return {pixels.data(), width, height, width}; }
};

struct TexturedModel {
  Model model;  // the print breaks the box's symmetry: symmetries = the identity only
  ModelTexturing texturing;
  std::vector<GreyImage> textures;  // per material; empty when the material has no map_Kd
};

}  // namespace sh
