// Wavefront OBJ text -> Model record.
//
// The OBJ may list polygons or any triangulation of them; what becomes of them is ModelFromMesh's
// (mesh_model.hpp). Only `v` and `f` statements are used; `vt`, `vn`, `o`, `g`, `s`, `usemtl`,
// ... are ignored.
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/model/mesh_model.hpp"
#include "recog/model/model.hpp"

namespace sh {

// Capacities and geometry limits: recog/model/mesh_model.hpp.

// `text` need not be NUL-terminated; `name` (may be null) is stored truncated to
// kMaxModelNameLength characters.
Result<Model> ParseObjModel(const char* text, size_t len, const char* name);

}  // namespace sh
