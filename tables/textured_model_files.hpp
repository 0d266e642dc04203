// Loading printed (textured) models from disk: the OBJ, its MTL and the texture images
// (host tools, the database builder and the simulator; never per frame).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
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

// Reads `path` (an OBJ), the MTL it names and the images the MTL's map_Kd name (relative to the
// MTL's folder). Images are converted to grey (ITU-R BT.601) and multiplied by the material's
// Kd luma. The model is named after the file stem. Errors name the file.
Result<TexturedModel> LoadTexturedModelFile(const std::string& path);

}  // namespace sh
