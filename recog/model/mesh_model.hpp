// A polygon mesh -> Model record: the geometry half of every model reader (OBJ here on the board
// and host, STL, PLY and 3MF through tools/tablegen/cad_import on the host).
//
// The mesh may list polygons or any triangulation of them: adjacent coplanar polygons are merged
// into one face, corners are the vertices where the surface bends (vertices inside a flat face or
// along a straight edge are dropped) and edges are the boundaries between non-coplanar faces.
// Polygons must be wound counter-clockwise seen from outside and form a closed 2-manifold surface.
// A merged face may have holes (a plate with a bore through it): see ModelFace.
// Symmetries are not computed here (n_symmetries stays 0).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// Input capacities (before merging): vertices, polygons, vertices per polygon, and polygon
// vertices in all.
inline constexpr int kMaxObjVertices = 256;
inline constexpr int kMaxObjPolygons = 512;
inline constexpr int kMaxObjPolygonVertices = 64;
inline constexpr int kMaxObjHalfEdges = 2048;
// Holes in one face (a plate with bores). A face with holes is stored as one outline that runs
// out to each hole along a bridge and back (ModelFace): two corners more per hole.
inline constexpr int kMaxFaceHoles = 8;

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
// face; adjacent polygons that bend by less than the least edge angle (kMinObjEdgeAngleDeg for
// OBJ) but are not within it are a face that is meant to be flat and is not, or a curved
// surface: refused, naming both and the distance.
inline constexpr double kObjPlanarityMm = 0.01;
inline constexpr double kObjPlanarityRelative = 1e-4;
inline constexpr double kMinObjEdgeAngleDeg = 2.0;

// Vertices and polygons in model millimetres, CSR style. About 12 KB.
struct PolygonMesh {
  int n_vertices = 0;
  Eigen::Vector3d vertices[kMaxObjVertices];
  int n_polygons = 0;
  int polygon_start[kMaxObjPolygons + 1] = {};  // into vertex_of
  int polygon_source[kMaxObjPolygons] = {};     // what messages call the polygon (an OBJ line)
  int n_half_edges = 0;
  uint16_t vertex_of[kMaxObjHalfEdges] = {};  // half-edge h starts at this vertex

  int size(int f) const { return polygon_start[f + 1] - polygon_start[f]; }
  int from(int h) const { return vertex_of[h]; }
  // Half-edges of polygon f are polygon_start[f] .. polygon_start[f+1]-1; h goes from
  // vertex_of[h] to the vertex of the next half-edge of the same polygon.
  int next_in_polygon(int h, int f) const {
    return h + 1 < polygon_start[f + 1] ? h + 1 : polygon_start[f];
  }
};

// How messages name the mesh and its polygons, and the least bend of an edge.
struct MeshModelOptions {
  const char* format = "OBJ";         // "OBJ lines 3 and 4: ..."
  const char* polygon_word = "line";  // "STL triangles 3 and 4: ..."
  const char* units_hint = "model units are millimetres";
  // Adjacent faces that bend by less than this (and are not coplanar) are facets of a curved
  // surface, joined by a smooth edge (ModelEdge::smooth); 0: none is.
  double smooth_below_deg = 0;
  // Adjacent faces that bend by less (and are not coplanar, nor smooth) are refused.
  double min_edge_angle_deg = kMinObjEdgeAngleDeg;
  // Null: the refusal names the edge, the vertex and its distance. Otherwise it is short and
  // ends in this ("under --sharp-deg 20: ...").
  const char* edge_angle_hint = nullptr;
};

// `name` (may be null) is stored truncated to kMaxModelNameLength characters.
Result<Model> ModelFromMesh(const PolygonMesh& mesh, const char* name,
                            const MeshModelOptions& options);

}  // namespace sh
