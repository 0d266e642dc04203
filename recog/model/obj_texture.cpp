#include "recog/model/obj_texture.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstring>

#include "recog/model/obj_model.hpp"
#include "recog/model/obj_text.hpp"

namespace sh {
namespace {

using obj::NumberError;

// Largest deviation (texture units) of a face's `vt` from its affine fit: a per-mille of the
// image, far above the rounding of exported coordinates and far below any non-affine mapping.
constexpr double kMaxUvFitError = 1e-3;

// Working data of one parse (about 60 KB, on the stack; model loading is not per-frame).
struct TexturedMesh {
  int n_vertices = 0;
  Eigen::Vector3d vertices[kMaxObjVertices];
  int n_tex = 0;
  Eigen::Vector2d tex[kMaxObjTexCoords];
  int n_polygons = 0;
  int polygon_start[kMaxObjPolygons + 1] = {};
  int polygon_line[kMaxObjPolygons] = {};
  int polygon_material[kMaxObjPolygons] = {};  // -1 before any usemtl
  int n_refs = 0;
  int vertex_of[kMaxObjHalfEdges] = {};
  int tex_of[kMaxObjHalfEdges] = {};  // -1: no vt
};

// The rest of the line after the keyword, trimmed, as a bounded C string.
bool CopyArgument(const char* p, const char* line_end, char* out, size_t capacity) {
  obj::SkipSpaces(p, line_end);
  const char* e = line_end;
  while (e > p && obj::IsSpace(e[-1])) --e;
  const size_t n = static_cast<size_t>(e - p);
  if (n == 0 || n >= capacity) return false;
  std::memcpy(out, p, n);
  out[n] = '\0';
  return true;
}

// The last whitespace-separated token of the line.
bool CopyLastToken(const char* p, const char* line_end, char* out, size_t capacity) {
  const char* e = line_end;
  while (e > p && obj::IsSpace(e[-1])) --e;
  const char* b = e;
  while (b > p && !obj::IsSpace(b[-1])) --b;
  const size_t n = static_cast<size_t>(e - b);
  if (n == 0 || n >= capacity) return false;
  std::memcpy(out, b, n);
  out[n] = '\0';
  return true;
}

Status ParseNumbers(const char*& p, const char* line_end, int line, int count, double* out,
                    const char* what) {
  for (int k = 0; k < count; ++k) {
    if (obj::ParseDouble(p, line_end, &out[k]) != NumberError::kNone) {
      return Status::Error(StatusCode::kInvalidArgument, "OBJ line %d: %s needs %d finite numbers",
                           line, what, count);
    }
  }
  return Status::Ok();
}

Status ParseText(const char* text, size_t len, TexturedMesh& mesh, ModelTexturing& tex) {
  int material = -1;
  for (obj::LineReader r(text, len); r.Next();) {
    const int line = r.line;
    const char*& p = r.rest;
    const char* const line_end = r.end;
    if (r.Is("v")) {
      if (mesh.n_vertices >= kMaxObjVertices) {
        return Status::Error(StatusCode::kResourceExhausted, "OBJ line %d: more than %d vertices",
                             line, kMaxObjVertices);
      }
      double xyz[3];
      SH_RETURN_IF_ERROR(ParseNumbers(p, line_end, line, 3, xyz, "vertex"));
      mesh.vertices[mesh.n_vertices++] = {xyz[0], xyz[1], xyz[2]};
    } else if (r.Is("vt")) {
      if (mesh.n_tex >= kMaxObjTexCoords) {
        return Status::Error(StatusCode::kResourceExhausted,
                             "OBJ line %d: more than %d texture coordinates", line,
                             kMaxObjTexCoords);
      }
      double uv[2];
      SH_RETURN_IF_ERROR(ParseNumbers(p, line_end, line, 2, uv, "texture coordinate (vt)"));
      // An optional third (w) coordinate is ignored.
      mesh.tex[mesh.n_tex++] = {uv[0], uv[1]};
    } else if (r.Is("usemtl")) {
      char name[kMaxObjMaterialNameLength + 1];
      if (!CopyArgument(p, line_end, name, sizeof(name))) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "OBJ line %d: usemtl needs a material name of at most %d characters",
                             line, kMaxObjMaterialNameLength);
      }
      material = -1;
      for (int m = 0; m < tex.n_materials; ++m) {
        if (std::strcmp(tex.materials[m].name, name) == 0) material = m;
      }
      if (material < 0) {
        if (tex.n_materials >= kMaxObjMaterials) {
          return Status::Error(StatusCode::kResourceExhausted,
                               "OBJ line %d: more than %d materials", line, kMaxObjMaterials);
        }
        material = tex.n_materials++;
        std::memcpy(tex.materials[material].name, name, sizeof(name));
      }
    } else if (r.Is("mtllib")) {
      if (!CopyArgument(p, line_end, tex.mtllib, sizeof(tex.mtllib))) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "OBJ line %d: mtllib needs a file name of at most %d characters", line,
                             kMaxObjFileNameLength);
      }
    } else if (r.Is("f")) {
      if (mesh.n_polygons >= kMaxObjPolygons) {
        return Status::Error(StatusCode::kResourceExhausted, "OBJ line %d: more than %d faces",
                             line, kMaxObjPolygons);
      }
      const int first = mesh.n_refs;
      for (;;) {
        long v = 0, vt = 0;
        const NumberError e = obj::ParseFaceVertex(p, line_end, &v, &vt);
        if (e == NumberError::kMissing) break;
        if (e != NumberError::kNone) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "OBJ line %d: malformed face vertex reference", line);
        }
        const long rv = obj::ResolveObjIndex(v, mesh.n_vertices);
        const long rt = vt == 0 ? -1 : obj::ResolveObjIndex(vt, mesh.n_tex);
        if (rv < 0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "OBJ line %d: face refers to vertex %ld but %d are defined", line, v,
                               mesh.n_vertices);
        }
        if (vt != 0 && rt < 0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "OBJ line %d: face refers to texture coordinate %ld but %d are "
                               "defined",
                               line, vt, mesh.n_tex);
        }
        if (mesh.n_refs >= kMaxObjHalfEdges || mesh.n_refs - first >= kMaxObjPolygonVertices) {
          return Status::Error(StatusCode::kResourceExhausted, "OBJ line %d: face too large", line);
        }
        mesh.vertex_of[mesh.n_refs] = static_cast<int>(rv);
        mesh.tex_of[mesh.n_refs] = static_cast<int>(rt);
        ++mesh.n_refs;
      }
      // Either every vertex of a polygon has its vt or none has.
      int with_tex = 0;
      for (int r = first; r < mesh.n_refs; ++r) with_tex += mesh.tex_of[r] >= 0 ? 1 : 0;
      if (with_tex != 0 && with_tex != mesh.n_refs - first) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "OBJ line %d: face gives texture coordinates for some vertices only",
                             line);
      }
      mesh.polygon_line[mesh.n_polygons] = line;
      mesh.polygon_material[mesh.n_polygons] = material;
      mesh.polygon_start[++mesh.n_polygons] = mesh.n_refs;
    }
  }
  return Status::Ok();
}

// Whether polygon pg lies on the plane of model face f and faces the same way (Newell normal).
bool PolygonOnFace(const TexturedMesh& mesh, int pg, const Model& model, int f, double tol) {
  const Eigen::Vector3d n = model.face_normal(f).cast<double>();
  Eigen::Vector3d newell = Eigen::Vector3d::Zero();
  const int b = mesh.polygon_start[pg], e = mesh.polygon_start[pg + 1];
  for (int r = b; r < e; ++r) {
    const Eigen::Vector3d& x = mesh.vertices[mesh.vertex_of[r]];
    const Eigen::Vector3d& y = mesh.vertices[mesh.vertex_of[r + 1 < e ? r + 1 : b]];
    newell += x.cross(y);
    if (std::fabs(n.dot(x) - model.faces[f].offset_mm) > tol) return false;
  }
  return newell.dot(n) > 0.0;
}

// Fits the face's affine map (a, b, 1) -> uv in the face frame (origin o, axes u, w) over the
// (vertex, vt) pairs of its polygons.
Status FitFaceMap(const TexturedMesh& mesh, const Model& model, int f, FaceTextureMap* map) {
  const ModelFace& face = model.faces[f];
  const Eigen::Vector3d n = model.face_normal(f).cast<double>();
  const Eigen::Vector3d o = model.corner(face.vertices[0]).cast<double>();
  const Eigen::Vector3d u = (model.corner(face.vertices[1]).cast<double>() - o).normalized();
  const Eigen::Vector3d w = n.cross(u);
  // Model size, for the coplanarity tolerance.
  double extent = 1.0;
  for (int c = 0; c < model.n_corners; ++c) {
    extent = std::max(extent, model.corner(c).cast<double>().norm());
  }
  const double tol = 1e-4 * extent;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> atb = Eigen::Matrix<double, 3, 2>::Zero();
  int pairs = 0, material = -2, untextured = 0, line = 0;
  for (int pg = 0; pg < mesh.n_polygons; ++pg) {
    if (!PolygonOnFace(mesh, pg, model, f, tol)) continue;
    const int b = mesh.polygon_start[pg], e = mesh.polygon_start[pg + 1];
    line = mesh.polygon_line[pg];
    if (mesh.tex_of[b] < 0) {
      ++untextured;
      continue;
    }
    if (material != -2 && material != mesh.polygon_material[pg]) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "OBJ line %d: face %d of the model mixes materials", line, f);
    }
    material = mesh.polygon_material[pg];
    for (int r = b; r < e; ++r) {
      const Eigen::Vector3d d = mesh.vertices[mesh.vertex_of[r]] - o;
      const Eigen::Vector3d a(d.dot(u), d.dot(w), 1.0);
      ata += a * a.transpose();
      atb += a * mesh.tex[mesh.tex_of[r]].transpose();
      ++pairs;
    }
  }
  *map = FaceTextureMap{};
  if (pairs == 0) return Status::Ok();  // untextured face
  if (untextured > 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "OBJ line %d: face %d of the model has polygons with and without texture "
                         "coordinates",
                         line, f);
  }
  if (material < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "OBJ line %d: textured face %d of the model has no material (usemtl)",
                         line, f);
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(ata);
  if (lu.rank() < 3) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "OBJ line %d: face %d of the model has degenerate texture coordinates",
                         line, f);
  }
  const Eigen::Matrix<double, 3, 2> coef = lu.solve(atb);  // uv = coef^T (a, b, 1)
  double max_err = 0.0;
  for (int pg = 0; pg < mesh.n_polygons; ++pg) {
    const int b = mesh.polygon_start[pg], e = mesh.polygon_start[pg + 1];
    if (mesh.tex_of[b] < 0 || !PolygonOnFace(mesh, pg, model, f, tol)) continue;
    for (int r = b; r < e; ++r) {
      const Eigen::Vector3d d = mesh.vertices[mesh.vertex_of[r]] - o;
      const Eigen::Vector3d a(d.dot(u), d.dot(w), 1.0);
      max_err = std::max(max_err, (coef.transpose() * a - mesh.tex[mesh.tex_of[r]]).norm());
    }
  }
  if (max_err > kMaxUvFitError) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "OBJ line %d: texture coordinates of face %d of the model are not one "
                         "planar (affine) mapping (deviation %.4f)",
                         line, f, max_err);
  }
  map->material = static_cast<int8_t>(material);
  map->max_fit_error = static_cast<float>(max_err);
  for (int r = 0; r < 2; ++r) {
    const Eigen::Vector3d g = coef(0, r) * u + coef(1, r) * w;  // gradient of the coordinate
    map->uv_from_model[4 * r + 0] = static_cast<float>(g.x());
    map->uv_from_model[4 * r + 1] = static_cast<float>(g.y());
    map->uv_from_model[4 * r + 2] = static_cast<float>(g.z());
    map->uv_from_model[4 * r + 3] = static_cast<float>(coef(2, r) - g.dot(o));
  }
  return Status::Ok();
}

}  // namespace

Result<ModelTexturing> ParseObjTexturing(const char* text, size_t len, const Model& model) {
  TexturedMesh mesh;
  ModelTexturing tex;
  SH_RETURN_IF_ERROR(ParseText(text, len, mesh, tex));
  for (int f = 0; f < model.n_faces; ++f)
    SH_RETURN_IF_ERROR(FitFaceMap(mesh, model, f, &tex.faces[f]));
  return tex;
}

Status ParseMtl(const char* text, size_t len, ModelTexturing* texturing) {
  int current = -1;  // material being defined, or -1 for one the OBJ does not use
  bool in_material = false;
  for (obj::LineReader r(text, len); r.Next();) {
    const int line = r.line;
    const char*& p = r.rest;
    const char* const line_end = r.end;
    if (r.Is("newmtl")) {
      char name[kMaxObjMaterialNameLength + 1];
      if (!CopyArgument(p, line_end, name, sizeof(name))) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "MTL line %d: newmtl needs a name of at most %d characters", line,
                             kMaxObjMaterialNameLength);
      }
      in_material = true;
      current = -1;
      for (int m = 0; m < texturing->n_materials; ++m) {
        if (std::strcmp(texturing->materials[m].name, name) == 0) current = m;
      }
    } else if (r.Is("map_Kd")) {
      if (!in_material) {
        return Status::Error(StatusCode::kInvalidArgument, "MTL line %d: map_Kd before newmtl",
                             line);
      }
      char file[kMaxObjFileNameLength + 1];
      if (!CopyLastToken(p, line_end, file, sizeof(file))) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "MTL line %d: map_Kd needs a file name of at most %d characters", line,
                             kMaxObjFileNameLength);
      }
      if (current >= 0) std::memcpy(texturing->materials[current].map_kd, file, sizeof(file));
    } else if (r.Is("Kd")) {
      if (!in_material) {
        return Status::Error(StatusCode::kInvalidArgument, "MTL line %d: Kd before newmtl", line);
      }
      double kd[3];
      for (double& c : kd) {
        if (obj::ParseDouble(p, line_end, &c) != NumberError::kNone || c < 0.0 || c > 1.0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "MTL line %d: Kd needs three numbers in [0, 1]", line);
        }
      }
      if (current >= 0) {
        for (int k = 0; k < 3; ++k) texturing->materials[current].kd[k] = static_cast<float>(kd[k]);
      }
    }
  }
  return Status::Ok();
}

}  // namespace sh
