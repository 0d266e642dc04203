// A polyhedral object model: corners, edges and faces in model millimetres.
//
// `Model` is a fixed-layout, trivially copyable record: it is what the table blob stores in its
// model directory and what code reads in place from the blob, so its layout is part of the blob
// format (docs/tables.md). All floats are IEEE-754 binary32, little-endian.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <type_traits>

namespace sh {

// Sized for a 48-sided prism (a can: 96 corners, 144 edges, 50 faces, two 48-gon caps, and a
// dihedral symmetry group of 96 rotations) with room for somewhat finer outlines. Corner
// indices are stored as uint8_t, edge indices elsewhere too: both capacities stay below 256.
inline constexpr int kMaxModelCorners = 128;
inline constexpr int kMaxModelEdges = 192;
inline constexpr int kMaxModelFaces = 64;
inline constexpr int kMaxFaceVertices = 64;
inline constexpr int kMaxModelSymmetries = 96;
inline constexpr int kMaxModelNameLength = 31;

// A smooth edge joins two facets of a tessellated curved surface (a bore, a fillet, a can's
// side: facets that bend by less than the sharp angle `tables build --sharp-deg` gives). The
// image shows it only where it is a silhouette (one of its faces turned to the camera, the other
// away); it is never hashed, and neither are the corners it touches (ModelFeatures).
struct ModelEdge {
  uint8_t a = 0, b = 0;          // corner indices
  uint8_t face0 = 0, face1 = 0;  // the two faces that meet at this edge
  uint8_t smooth = 0;            // 1: a facet edge of a curved surface; 0: a feature edge
};

// A face with holes is one outline that runs from its outer outline to each hole along a bridge,
// round the hole and back (a corner pair listed twice, docs/tables.md): even-odd tests of the
// polygon see the holes open. The bridges are no edges.
struct ModelFace {
  uint8_t n_vertices = 0;
  uint8_t vertices[kMaxFaceVertices] = {};  // corner indices, counter-clockwise from outside
  float normal[3] = {};                     // outward unit normal
  float offset_mm = 0;                      // plane: normal . x = offset_mm
};

struct Model {
  char name[kMaxModelNameLength + 1] = {};  // NUL-terminated (OBJ file stem)
  uint16_t n_corners = 0;
  uint16_t n_edges = 0;
  uint16_t n_faces = 0;
  uint16_t n_symmetries = 0;  // proper rotations mapping the model onto itself (identity first)
  float corners_mm[kMaxModelCorners][3] = {};
  ModelEdge edges[kMaxModelEdges] = {};
  ModelFace faces[kMaxModelFaces] = {};
  float symmetries[kMaxModelSymmetries][9] = {};  // row-major rotation matrices

  Eigen::Vector3f corner(int i) const {
    return {corners_mm[i][0], corners_mm[i][1], corners_mm[i][2]};
  }
  Eigen::Vector3f face_normal(int f) const {
    return {faces[f].normal[0], faces[f].normal[1], faces[f].normal[2]};
  }
  Eigen::Matrix3f symmetry(int k) const {
    return Eigen::Map<const Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(symmetries[k]);
  }
};

static_assert(std::is_trivially_copyable_v<Model>);
static_assert(kMaxModelCorners <= 256 && kMaxModelEdges <= 256, "indices are uint8_t");
static_assert(std::is_standard_layout_v<Model>);
// The record is part of every blob format (docs/tables.md): a change of layout is a new version.
static_assert(sizeof(ModelEdge) == 5 && sizeof(Model) == 11368, "Model is a blob format");

}  // namespace sh
