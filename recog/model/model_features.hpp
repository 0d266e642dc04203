// Which of a model's corners and edges geometric hashing uses: the stereo hash tables, the
// one-image aspect tables and the correspondences that score and refine a pose.
//
// Of a polyhedron, every corner and edge. Of a part with curved surfaces (ModelEdge::smooth),
// a tessellation vertex is no corner an image shows and a chord of a curved outline no straight
// line: a corner is hashed when no smooth edge meets it, an edge is hashed as a line when it is
// not smooth and at least one of its ends is a hashed corner (a bore's rim chords are not; the
// straight edge of a plate that runs into a fillet is). The verifier still sees the rest: smooth
// edges as silhouettes, rim chords as the outline they trace.
#pragma once

#include <bitset>

#include "recog/model/model.hpp"

namespace sh {

struct ModelFeatures {
  std::bitset<kMaxModelCorners> corners;  // hashed corners
  std::bitset<kMaxModelEdges> lines;      // edges hashed as lines
  int n_smooth_edges = 0;

  bool corner(int i) const { return corners.test(static_cast<size_t>(i)); }
  bool line(int e) const { return lines.test(static_cast<size_t>(e)); }
  int n_corners() const { return static_cast<int>(corners.count()); }
  int n_lines() const { return static_cast<int>(lines.count()); }
};

// O(corners + edges), no allocation: cheap enough to take where it is needed. The record must
// have been checked (indices in range).
ModelFeatures FeaturesOf(const Model& model);

// Whether face f borders a smooth edge: a facet of a curved surface.
bool FaceIsCurved(const Model& model, int f);

}  // namespace sh
