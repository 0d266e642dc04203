// Wavefront OBJ text -> Model record.
//
// The OBJ may list polygons or any triangulation of them: adjacent coplanar polygons are merged
// into one face, corners are the vertices where the surface bends (vertices inside a flat face or
// along a straight edge are dropped) and edges are the boundaries between non-coplanar faces.
// Faces must be wound counter-clockwise seen from outside and form a closed 2-manifold surface.
// Only `v` and `f` statements are used; `vt`, `vn`, `o`, `g`, `s`, `usemtl`, ... are ignored.
// Symmetries are not computed here (n_symmetries stays 0).
#pragma once

#include <cstddef>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// Input capacities of the parser (before merging): vertices, polygons, and vertices per polygon.
inline constexpr int kMaxObjVertices = 256;
inline constexpr int kMaxObjPolygons = 512;
inline constexpr int kMaxObjPolygonVertices = 64;
inline constexpr int kMaxObjHalfEdges = 2048;

// `text` need not be NUL-terminated; `name` (may be null) is stored truncated to
// kMaxModelNameLength characters.
Result<Model> ParseObjModel(const char* text, size_t len, const char* name);

}  // namespace sh
