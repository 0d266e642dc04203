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

// Geometry limits. Coordinates beyond +-kMaxObjCoordinateMm are a unit mistake (metres vs
// millimetres the other way round) or garbage; a model more than kMaxObjSizeMm across does not
// fit the hash tables, which store model millimetres in Q10.6 (+-512 mm); one below
// kMinObjSizeMm is degenerate.
inline constexpr double kMaxObjCoordinateMm = 10000.0;
inline constexpr double kMaxObjSizeMm = 500.0;
inline constexpr double kMinObjSizeMm = 1.0;
// A face is flat when all its vertices lie within the planarity tolerance of its plane:
// max(kObjPlanarityMm, kObjPlanarityRelative x model size), which admits coordinates printed
// with a few decimals. Adjacent polygons within the tolerance of each other's planes are one
// face; adjacent polygons that bend by less than kMinObjEdgeAngleDeg but are not within it are
// a face that is meant to be flat and is not (a real edge that shallow would not show in an
// image either): refused, naming both and the distance.
inline constexpr double kObjPlanarityMm = 0.01;
inline constexpr double kObjPlanarityRelative = 1e-4;
inline constexpr double kMinObjEdgeAngleDeg = 2.0;

// `text` need not be NUL-terminated; `name` (may be null) is stored truncated to
// kMaxModelNameLength characters.
Result<Model> ParseObjModel(const char* text, size_t len, const char* name);

}  // namespace sh
