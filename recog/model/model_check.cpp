#include "recog/model/model_check.hpp"

#include <cmath>

#include "recog/base/printable.hpp"

namespace sh {

Status ValidateModelRecord(const Model& m, uint32_t index, const char* blob) {
  if (m.name[kMaxModelNameLength] != '\0' || m.name[0] == '\0') {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: model %u has no valid name", blob,
                         index);
  }
  // The name is printed escaped: a damaged one must not put control bytes into a log.
  char name[kPrintableNameBytes];
  Printable(m.name, sizeof(m.name), name, sizeof(name));
  if (m.n_corners < 3 || m.n_corners > kMaxModelCorners || m.n_edges > kMaxModelEdges ||
      m.n_faces > kMaxModelFaces || m.n_symmetries == 0 || m.n_symmetries > kMaxModelSymmetries) {
    return Status::Error(StatusCode::kDataLoss, "%s corrupt: model '%s' counts out of range", blob,
                         name);
  }
  for (int i = 0; i < m.n_corners; ++i) {
    for (float c : m.corners_mm[i]) {
      if (!std::isfinite(c)) {
        return Status::Error(StatusCode::kDataLoss,
                             "%s corrupt: model '%s' has a non-finite corner", blob, name);
      }
    }
  }
  for (int i = 0; i < m.n_edges; ++i) {
    const ModelEdge& e = m.edges[i];
    if (e.a >= m.n_corners || e.b >= m.n_corners || e.face0 >= m.n_faces || e.face1 >= m.n_faces) {
      return Status::Error(StatusCode::kDataLoss,
                           "%s corrupt: model '%s' edge %d indexes out of range", blob, name, i);
    }
    if (e.smooth > 1) {
      return Status::Error(StatusCode::kDataLoss,
                           "%s corrupt: model '%s' edge %d has smooth flag %u (0 or 1)", blob, name,
                           i, e.smooth);
    }
  }
  for (int f = 0; f < m.n_faces; ++f) {
    const ModelFace& face = m.faces[f];
    if (face.n_vertices < 3 || face.n_vertices > kMaxFaceVertices) {
      return Status::Error(StatusCode::kDataLoss, "%s corrupt: model '%s' face %d has %u vertices",
                           blob, name, f, face.n_vertices);
    }
    for (int k = 0; k < face.n_vertices; ++k) {
      if (face.vertices[k] >= m.n_corners) {
        return Status::Error(StatusCode::kDataLoss,
                             "%s corrupt: model '%s' face %d indexes out of range", blob, name, f);
      }
    }
    for (float c : face.normal) {
      if (!std::isfinite(c)) {
        return Status::Error(StatusCode::kDataLoss,
                             "%s corrupt: model '%s' face %d has a non-finite normal", blob, name,
                             f);
      }
    }
  }
  return Status::Ok();
}

}  // namespace sh
