#include "recog/model/obj_model.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>

#include "recog/model/obj_text.hpp"

namespace sh {
namespace {

// Tokenising (obj_text.hpp).
using obj::IsSpace;
using obj::NumberError;
using obj::ParseDouble;
using obj::SkipSpaces;

// Characters of the vertex index at the start of a face token, for messages: indices are quoted
// as written, never as the number they saturated at.
int IndexLength(const char* token, const char* end) {
  const char* p = token;
  while (p < end && *p != '/' && !IsSpace(*p)) ++p;
  return static_cast<int>(p - token);
}

Status ParseText(const char* text, size_t len, PolygonMesh& mesh) {
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
      for (int k = 0; k < 3; ++k) {
        switch (ParseDouble(p, line_end, &xyz[k])) {
          case NumberError::kNone:
            break;
          case NumberError::kMissing:
            return Status::Error(StatusCode::kInvalidArgument,
                                 "OBJ line %d: vertex needs 3 coordinates", line);
          case NumberError::kMalformed:
            return Status::Error(StatusCode::kInvalidArgument,
                                 "OBJ line %d: malformed vertex coordinate", line);
          case NumberError::kNonFinite:
            return Status::Error(StatusCode::kInvalidArgument,
                                 "OBJ line %d: non-finite vertex coordinate", line);
        }
      }
      for (int k = 0; k < 3; ++k) {
        if (std::abs(xyz[k]) > kMaxObjCoordinateMm) {
          return Status::Error(StatusCode::kOutOfRange,
                               "OBJ line %d: coordinate %g mm is outside +-%g mm (model units "
                               "are millimetres)",
                               line, xyz[k], kMaxObjCoordinateMm);
        }
      }
      mesh.vertices[mesh.n_vertices++] = {xyz[0], xyz[1], xyz[2]};
    } else if (r.Is("f")) {
      if (mesh.n_polygons >= kMaxObjPolygons) {
        return Status::Error(StatusCode::kResourceExhausted, "OBJ line %d: more than %d faces",
                             line, kMaxObjPolygons);
      }
      const int first = mesh.n_half_edges;
      for (;;) {
        SkipSpaces(p, line_end);
        if (p == line_end) break;
        // Token "v", "v/vt", "v/vt/vn" or "v//vn": only v matters.
        const char* token = p;
        long index = 0, vt = 0;
        if (obj::ParseFaceVertex(p, line_end, &index, &vt) != NumberError::kNone) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "OBJ line %d: malformed face vertex index", line);
        }
        const long resolved = obj::ResolveObjIndex(index, mesh.n_vertices);
        if (resolved < 0) {
          return Status::Error(StatusCode::kInvalidArgument,
                               "OBJ line %d: face refers to vertex %.*s but %d are defined", line,
                               IndexLength(token, line_end), token, mesh.n_vertices);
        }
        if (mesh.n_half_edges - first >= kMaxObjPolygonVertices ||
            mesh.n_half_edges >= kMaxObjHalfEdges) {
          return Status::Error(StatusCode::kResourceExhausted,
                               "OBJ line %d: face too large (limits: %d vertices per face, %d "
                               "face vertices in total)",
                               line, kMaxObjPolygonVertices, kMaxObjHalfEdges);
        }
        mesh.vertex_of[mesh.n_half_edges++] = static_cast<uint16_t>(resolved);
      }
      if (mesh.n_half_edges - first < 3) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "OBJ line %d: face has fewer than 3 vertices", line);
      }
      mesh.polygon_source[mesh.n_polygons] = line;
      mesh.polygon_start[++mesh.n_polygons] = mesh.n_half_edges;
    }
  }
  if (mesh.n_polygons == 0) {
    return Status::Error(StatusCode::kInvalidArgument, "OBJ has no faces");
  }
  return Status::Ok();
}

}  // namespace

Result<Model> ParseObjModel(const char* text, size_t len, const char* name) {
  if (text == nullptr && len > 0) {
    return Status::Error(StatusCode::kInvalidArgument, "OBJ text is null");
  }
  // About 12 KB; model loading is not per-frame.
  PolygonMesh mesh;
  SH_RETURN_IF_ERROR(ParseText(text, len, mesh));
  return ModelFromMesh(mesh, name, MeshModelOptions{});
}

}  // namespace sh
