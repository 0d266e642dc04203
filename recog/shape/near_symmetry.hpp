// Near symmetries of a model: half turns that map its corners almost, but not exactly, onto
// themselves. The L bracket (legs 50 and 45 mm) turned half a turn about the bisector of its
// profile has nearly the same silhouette and edges: the view search and a refinement that starts
// there can settle on it, 180 degrees from the truth, with most edges confirmed. The shape path
// refines the turned pose of an accepted part too and keeps the one the images explain better
// (shape_recognizer.cpp).
//
// Candidates start as the half turns about the principal axes of the corners, about their
// centroid (a near symmetry leaves its axis close to a principal axis of the corner scatter),
// and are fitted as rigid motions to the corners they bring each corner nearest to (a few
// rounds of closest corners and Kabsch). One is near when every moved corner lies within
// max_offset_share of the model's radius of a corner, and exact when its rotation is within 10
// degrees of one of the model's symmetry group (the same pose already) or it moves no corner.
#pragma once

#include <Eigen/Core>

#include "recog/model/model.hpp"

namespace sh {

inline constexpr int kMaxNearSymmetries = 3;

// NOLINTNEXTLINE(bugprone-reserved-identifier): clang-tidy 14 names the implicit array copy's index
struct NearSymmetries {
  int n = 0;
  // model_T_model: x -> R[k] x + t_mm[k].
  Eigen::Matrix3f R[kMaxNearSymmetries];
  Eigen::Vector3f t_mm[kMaxNearSymmetries];
  float offset_mm[kMaxNearSymmetries] = {};  // largest distance of a turned corner to a corner
};

// No allocation; a model without corners has none.
NearSymmetries FindNearSymmetries(const Model& model, float max_offset_share = 0.2f);

}  // namespace sh
