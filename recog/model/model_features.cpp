#include "recog/model/model_features.hpp"

namespace sh {

ModelFeatures FeaturesOf(const Model& model) {
  ModelFeatures f;
  std::bitset<kMaxModelCorners> on_smooth_edge;
  for (int e = 0; e < model.n_edges; ++e) {
    const ModelEdge& edge = model.edges[e];
    if (!edge.smooth) continue;
    ++f.n_smooth_edges;
    on_smooth_edge.set(edge.a);
    on_smooth_edge.set(edge.b);
  }
  for (int i = 0; i < model.n_corners; ++i) {
    if (!on_smooth_edge.test(static_cast<size_t>(i))) f.corners.set(static_cast<size_t>(i));
  }
  for (int e = 0; e < model.n_edges; ++e) {
    const ModelEdge& edge = model.edges[e];
    if (!edge.smooth && (f.corner(edge.a) || f.corner(edge.b))) f.lines.set(static_cast<size_t>(e));
  }
  return f;
}

bool FaceIsCurved(const Model& model, int f) {
  for (int e = 0; e < model.n_edges; ++e) {
    const ModelEdge& edge = model.edges[e];
    if (edge.smooth && (edge.face0 == f || edge.face1 == f)) return true;
  }
  return false;
}

}  // namespace sh
