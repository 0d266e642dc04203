#include "tools/tablegen/cad_import.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <memory>

#include "recog/model/mesh_model.hpp"
#include "tables/input_file.hpp"
#include "tables/model_files.hpp"

namespace sh {
namespace {

// "STL", "PLY", "3MF", "OBJ": what messages call a file of extension `ext` (kModelFileExtensions).
std::string FormatName(const char* ext) {
  std::string name = ext == nullptr ? "mesh" : ext + 1;
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

// Index of a vertex within kCadWeldMm of p among the first n, or -1. Quadratic, over at most
// kMaxObjVertices welded vertices.
int FindWelded(const PolygonMesh& mesh, const Eigen::Vector3d& p) {
  for (int i = 0; i < mesh.n_vertices; ++i) {
    if ((mesh.vertices[i] - p).squaredNorm() <= kCadWeldMm * kCadWeldMm) return i;
  }
  return -1;
}

// The scene's triangles, in millimetres, with welded vertices. Points and line segments
// (some exporters add them) carry no surface and are skipped.
Status SceneToMesh(const aiScene& scene, const std::string& format, double mm_per_unit,
                   PolygonMesh& mesh) {
  const char* what = format.c_str();
  int triangles = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    for (unsigned f = 0; f < scene.mMeshes[m]->mNumFaces; ++f) {
      triangles += scene.mMeshes[m]->mFaces[f].mNumIndices == 3 ? 1 : 0;
    }
  }
  if (triangles > kMaxObjPolygons) {
    return Status::Error(StatusCode::kResourceExhausted,
                         "%s has %d triangles; at most %d (a polyhedral model's capacity)", what,
                         triangles, kMaxObjPolygons);
  }
  int triangle = 0;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& in = *scene.mMeshes[m];
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      const aiFace& face = in.mFaces[f];
      if (face.mNumIndices != 3) continue;
      ++triangle;
      const int first = mesh.n_half_edges;
      for (unsigned k = 0; k < 3; ++k) {
        const aiVector3D& v = in.mVertices[face.mIndices[k]];
        const Eigen::Vector3d p = Eigen::Vector3d(v.x, v.y, v.z) * mm_per_unit;
        if (!p.allFinite()) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "%s triangle %d: non-finite vertex coordinate", what, triangle);
        }
        if (p.cwiseAbs().maxCoeff() > kMaxObjCoordinateMm) {
          return Status::Error(StatusCode::kOutOfRange,
                               "%s triangle %d: coordinate %g mm is outside +-%g mm (give the "
                               "file's length unit with --units)",
                               what, triangle, p.cwiseAbs().maxCoeff(), kMaxObjCoordinateMm);
        }
        int index = FindWelded(mesh, p);
        if (index < 0) {
          if (mesh.n_vertices >= kMaxObjVertices) {
            return Status::Error(StatusCode::kResourceExhausted,
                                 "%s has more than %d distinct vertices", what, kMaxObjVertices);
          }
          index = mesh.n_vertices;
          mesh.vertices[mesh.n_vertices++] = p;
        }
        mesh.vertex_of[mesh.n_half_edges++] = static_cast<uint16_t>(index);
      }
      // A triangle whose vertices weld together is a sliver of no area: left out, as the
      // neighbours it touches already close the surface across it.
      const uint16_t* v = &mesh.vertex_of[first];
      if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) {
        mesh.n_half_edges = first;
        continue;
      }
      mesh.polygon_source[mesh.n_polygons] = triangle;
      mesh.polygon_start[++mesh.n_polygons] = mesh.n_half_edges;
    }
  }
  if (mesh.n_polygons == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "%s has no triangles", what);
  }
  return Status::Ok();
}

// The centre of volume of the closed, outward-wound triangle mesh: the volume-weighted mean of the
// centroids of the tetrahedra each triangle spans with a reference vertex.
Eigen::Vector3d VolumeCentroid(const PolygonMesh& mesh) {
  const Eigen::Vector3d& o = mesh.vertices[0];
  double volume6 = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int f = 0; f < mesh.n_polygons; ++f) {
    const int h = mesh.polygon_start[f];
    const Eigen::Vector3d a = mesh.vertices[mesh.from(h)] - o;
    const Eigen::Vector3d b = mesh.vertices[mesh.from(h + 1)] - o;
    const Eigen::Vector3d c = mesh.vertices[mesh.from(h + 2)] - o;
    const double v = a.dot(b.cross(c));
    volume6 += v;
    moment += v * (a + b + c) / 4.0;
  }
  return o + moment / volume6;  // volume6 > 0: ModelFromMesh checked the winding
}

}  // namespace

void MoveModelOrigin(Model& model, const Eigen::Vector3d& origin_mm) {
  const Eigen::Vector3f o = origin_mm.cast<float>();
  for (int i = 0; i < model.n_corners; ++i) {
    for (int k = 0; k < 3; ++k) model.corners_mm[i][k] -= o[k];
  }
  for (int f = 0; f < model.n_faces; ++f) model.faces[f].offset_mm -= model.face_normal(f).dot(o);
}

bool ParseLengthUnit(const char* text, double* mm_per_unit) {
  static constexpr struct {
    const char* name;
    double mm;
  } kUnits[] = {{"mm", 1.0}, {"cm", 10.0}, {"m", 1000.0}, {"in", 25.4}};
  for (const auto& u : kUnits) {
    if (std::strcmp(text, u.name) == 0) {
      *mm_per_unit = u.mm;
      return true;
    }
  }
  return false;
}

bool IsCadFileName(const std::string& path) {
  return ModelFileExtension(path) != nullptr && !IsObjModelFile(path);
}

Result<Model> ImportCadModel(const std::string& path, const CadImportOptions& options,
                             CadImportReport* report) {
  const char* ext = ModelFileExtension(path);
  const std::string format = FormatName(ext);
  std::string bytes;
  SH_RETURN_IF_ERROR(ReadInputFile(path, format.c_str(), size_t(kMaxCadFileBytes), &bytes));
  SH_ASSIGN_OR_RETURN(const std::string stem, ModelNameOfFile(path));

  Assimp::Importer importer;
  // Only positions matter: normals, colours and texture coordinates are dropped before
  // post-processing, and nodes' transforms are baked into the vertices.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_COLORS |
                                                          aiComponent_TEXCOORDS |
                                                          aiComponent_TANGENTS_AND_BITANGENTS);
  const aiScene* scene = importer.ReadFileFromMemory(
      bytes.data(), bytes.size(),
      aiProcess_RemoveComponent | aiProcess_Triangulate | aiProcess_PreTransformVertices,
      ext == nullptr ? "" : ext + 1);
  if (scene == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "%s: not a readable %s file: %s",
                         path.c_str(), format.c_str(), importer.GetErrorString());
  }
  auto mesh = std::make_unique<PolygonMesh>();
  Status read = SceneToMesh(*scene, format, options.mm_per_unit, *mesh);
  if (!read.ok()) return read.WithContext("%s", path.c_str());

  char units_hint[48];
  std::snprintf(units_hint, sizeof(units_hint), "read in %s: give its unit with --units",
                options.unit);
  MeshModelOptions mesh_options;
  mesh_options.format = format.c_str();
  mesh_options.polygon_word = "triangle";
  mesh_options.units_hint = units_hint;
  // Facets that bend by less than the sharp angle are a curved surface: smooth edges.
  mesh_options.smooth_below_deg = options.sharp_deg;
  Result<Model> model = ModelFromMesh(*mesh, stem.c_str(), mesh_options);
  if (!model.ok()) return model.status().WithContext("%s", path.c_str());
  CadImportReport done;
  done.centroid_in_file_mm = VolumeCentroid(*mesh);
  if (options.origin == ModelOrigin::kCentroid) {
    done.origin_in_file_mm = done.centroid_in_file_mm;
    MoveModelOrigin(*model, done.origin_in_file_mm);
  }
  if (report != nullptr) *report = done;
  return model;
}

Result<Model> ImportModelFile(const std::string& path, const CadImportOptions& options,
                              CadImportReport* report) {
  if (IsObjModelFile(path) && !options.obj_through_import) return LoadModelFile(path);
  return ImportCadModel(path, options, report);
}

}  // namespace sh
