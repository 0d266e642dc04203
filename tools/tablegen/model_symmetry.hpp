// The rotation symmetry group of a polyhedral model, and how it permutes corners and edges.
//
// Used offline: to store each class of symmetric model bases once (bases related by a symmetry
// produce identical hash entries), and to fill Model::symmetries so that pose comparisons and
// duplicate detection can take the symmetry into account.
#pragma once

#include <vector>

#include "recog/model/model.hpp"

namespace sh {

struct SymmetryAction {
  Eigen::Matrix3f R;               // model_T_model rotation about the model origin
  std::vector<int> corner_map;     // corner i -> corner corner_map[i]
  std::vector<int> edge_map;       // edge e -> edge edge_map[e]
  std::vector<bool> edge_flipped;  // true if a->b maps to the stored edge's b->a
};

// All proper rotations (about the centroid-origin) that map the corner set and the edge set onto
// themselves, identity first. Tolerance in millimetres.
std::vector<SymmetryAction> FindSymmetries(const Model& model, float tolerance_mm = 1e-3f);

// Writes the rotations into model.symmetries / n_symmetries (at most kMaxModelSymmetries).
void StoreSymmetries(Model& model, const std::vector<SymmetryAction>& actions);

}  // namespace sh
