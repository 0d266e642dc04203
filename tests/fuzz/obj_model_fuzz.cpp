// libFuzzer target: the OBJ model reader (the board's and the host's) must return a Status for any
// input, never crash or read outside it; a model it accepts must pass the model-set reader's
// record check, and every edge must run between consecutive corners of both its faces' outlines
// (holes and their bridges included).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "recog/model/model_check.hpp"
#include "recog/model/obj_model.hpp"

namespace {

bool OnOutline(const sh::ModelFace& face, int a, int b) {
  for (int k = 0; k < face.n_vertices; ++k) {
    const int u = face.vertices[k], v = face.vertices[(k + 1) % face.n_vertices];
    if ((u == a && v == b) || (u == b && v == a)) return true;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Exactly sized heap copy so that ASan catches reads past the end (no terminating NUL).
  char* text = static_cast<char*>(std::malloc(size == 0 ? 1 : size));
  if (size > 0) std::memcpy(text, data, size);
  const sh::Result<sh::Model> parsed = sh::ParseObjModel(text, size, "fuzz");
  std::free(text);
  if (!parsed.ok()) return 0;
  sh::Model m = *parsed;
  // Symmetries are found by the table builder; the record check wants the identity at least.
  m.n_symmetries = 1;
  const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::memcpy(m.symmetries[0], identity, sizeof(identity));
  if (!sh::ValidateModelRecord(m, 0, "fuzz").ok()) std::abort();
  for (int e = 0; e < m.n_edges; ++e) {
    const sh::ModelEdge& edge = m.edges[e];
    if (!OnOutline(m.faces[edge.face0], edge.a, edge.b) ||
        !OnOutline(m.faces[edge.face1], edge.a, edge.b)) {
      std::abort();
    }
  }
  return 0;
}
