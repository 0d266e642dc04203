// Loading printed (textured) models from disk: the OBJ, its MTL and the texture images, decoded
// by the image codec of the host side (tools, tests and the simulator; never per frame).
#pragma once

#include <string>

#include "recog/base/status.hpp"
#include "recog/model/textured_model.hpp"

namespace sh {

// Reads `path` (an OBJ), the MTL it names and the images the MTL's map_Kd name (relative to the
// MTL's folder). Images are converted to grey (ITU-R BT.601) and multiplied by the material's
// Kd luma. The model is named after the file stem. Errors name the file.
Result<TexturedModel> LoadTexturedModelFile(const std::string& path);

}  // namespace sh
