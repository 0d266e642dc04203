// Loading model OBJ files from disk (host tools and firmware start-up, never per frame).
#pragma once

#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// The six reference objects in the order the thesis lists them; their index is the model id
// reported over CAN.
inline const char* const kReferenceModelNames[] = {"cube", "hexagon",  "wedge",
                                                   "star", "pentagon", "trapezium"};

// Reads one OBJ file; the model is named after the file stem.
Result<Model> LoadModelFile(const std::string& path);

// Reads `<dir>/<name>.obj` for each name, in that order.
Status LoadModels(const std::string& dir, const std::vector<std::string>& names,
                  std::vector<Model>* models);

// The reference set from `dir` (the repository's models/ folder).
Status LoadReferenceModels(const std::string& dir, std::vector<Model>* models);

}  // namespace sh
