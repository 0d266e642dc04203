// Models from CAD exports (host tools: `tables build`, `tables info`; the board reads blobs).
//
// STL (binary and ASCII), PLY, 3MF and OBJ are read with assimp, scaled to millimetres, their
// vertices welded within kCadWeldMm, and merged into faces, corners and edges exactly as an OBJ
// is (ModelFromMesh): coplanar triangles become one face, and adjacent faces that bend by at
// least the sharp angle meet at a feature edge. Facets that bend by less (a tessellated fillet,
// bore or cylinder) are a curved surface: each facet is a face, joined to the next by a smooth
// edge that the verifier sees only as a silhouette and hashing never uses (ModelEdge::smooth,
// recog/model/model_features.hpp). See docs/tables.md and docs/limits.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

// Files are read whole (through InputFile: regular files only, never blocking) up to this size,
// before assimp sees a byte; their triangles are bounded by kMaxObjPolygons after that.
inline constexpr long kMaxCadFileBytes = 8L << 20;
// Vertices closer than this (after scaling to millimetres) are one vertex: STL repeats every
// vertex once per triangle, and exporters print coordinates rounded.
inline constexpr double kCadWeldMm = 1e-3;
// The bend between adjacent facets, in degrees, below which they are not an edge: tessellated
// curves bend 3..15 degrees per facet in CAD exports, a machined edge 30 or more.
inline constexpr double kDefaultSharpDeg = 20.0;
inline constexpr double kMinSharpDeg = 2.0;
inline constexpr double kMaxSharpDeg = 89.0;

// Where the model's origin goes. Symmetries are rotations about the model origin
// (Model::symmetries), so a symmetric part is only known as such when its origin lies on its
// symmetry axes: the centroid always does, a CAD file's origin often does not (a corner).
enum class ModelOrigin : uint8_t {
  kFile,      // the file's own frame (default): poses are of the CAD frame, as for an OBJ
  kCentroid,  // the solid's centre of volume; poses are of that frame
};

struct CadImportOptions {
  double mm_per_unit = 1.0;  // --units: mm 1, cm 10, m 1000, in 25.4
  const char* unit = "mm";
  double sharp_deg = kDefaultSharpDeg;      // --sharp-deg
  ModelOrigin origin = ModelOrigin::kFile;  // --origin file|centroid
  // OBJ files are read by the board's own reader (millimetres, edges of 2 degrees and more) unless
  // a unit or a sharp angle was asked for.
  bool obj_through_import = false;
};

// "mm", "cm", "m" or "in" -> millimetres per unit; false for anything else.
bool ParseLengthUnit(const char* text, double* mm_per_unit);

// Whether `path` names a file this importer reads: .stl, .ply, .3mf (any case).
bool IsCadFileName(const std::string& path);

// What an import found besides the model: the solid's centroid in the file's frame, and where
// the model's origin lies in that frame (zero with ModelOrigin::kFile; the centroid with
// kCentroid), so that a pose can be taken back to the CAD frame:
// file_T_object = Translation(origin_in_file_mm) * model_T_object.
struct CadImportReport {
  Eigen::Vector3d centroid_in_file_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin_in_file_mm = Eigen::Vector3d::Zero();
};

// The model moved so that `origin_mm` (in its current frame) becomes its origin.
void MoveModelOrigin(Model& model, const Eigen::Vector3d& origin_mm);

// One model from a CAD export, named after its file stem.
Result<Model> ImportCadModel(const std::string& path, const CadImportOptions& options,
                             CadImportReport* report = nullptr);

// Any model file of a folder: OBJ through LoadModelFile (its own frame, no report) unless
// options say otherwise, the rest through ImportCadModel.
Result<Model> ImportModelFile(const std::string& path, const CadImportOptions& options,
                              CadImportReport* report = nullptr);

}  // namespace sh
