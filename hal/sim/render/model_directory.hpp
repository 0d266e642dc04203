// Loads the reference models (Wavefront OBJ files, e.g. the repository's models/ folder).
#pragma once

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh::render {

inline constexpr int kMaxModelFiles = 32;
inline constexpr long kMaxObjFileBytes = 1 << 20;

// Parses every *.obj file of `dir` in file-name order into models[0..capacity); each model is
// named after its file stem. Returns how many were loaded; any unreadable or invalid file fails
// the whole call with a message naming the file.
Result<int> LoadModelDirectory(const char* dir, Model* models, int capacity);

// Index of the model called `name`, or -1.
int FindModel(const Model* models, int n_models, const char* name);

}  // namespace sh::render
