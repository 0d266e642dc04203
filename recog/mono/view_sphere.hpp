// The viewing sphere around a model (thesis 6.3): a tessellation by polar angle theta (from the
// model's z axis) and azimuth phi, with the number of azimuths at each polar angle growing with
// sin(theta) so that the views are spread about evenly, and local refinement by four views half
// way to the neighbours. Views related by a rotation symmetry of the model give the same
// projection up to a rotation in the image, so only one part of the sphere (a fundamental
// domain of the symmetry group) is kept.
//
// Offline and at start-up only; bounded arrays, no heap.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "recog/model/model.hpp"

namespace sh {

// One viewing direction: the unit vector from the model origin towards the camera, in the model
// frame, and where it sits in the tessellation.
struct ViewDirection {
  Eigen::Vector3f dir_model{0, 0, 1};
  float theta_deg = 0;    // polar angle from the model's +z axis
  float phi_deg = 0;      // azimuth from the model's +x axis towards +y
  float spacing_deg = 0;  // grid spacing at this view's level
  uint8_t level = 0;      // 0: initial grid; k: k-th refinement
};

// Unit vector of (theta, phi) in degrees.
Eigen::Vector3f ViewVector(float theta_deg, float phi_deg);

// The initial grid with `spacing_deg` between neighbouring polar angles (0 and 180 included)
// and about the same arc between neighbouring azimuths. Writes at most `capacity` views and
// returns the number the full grid has (more than capacity: the grid did not fit).
int InitialViewGrid(float spacing_deg, ViewDirection* out, int capacity);

// The four views half way (half the spacing in polar angle, half the spacing as arc in
// azimuth) diagonally around `view`, at the next level with half its spacing. At a pole the
// four are spread evenly in azimuth.
void RefinementViews(const ViewDirection& view, ViewDirection out[4]);

// True if `dir_model` lies within margin_deg of the kept part of the sphere: the views that no
// rotation of the model's symmetry group (Model::symmetries) moves further along a fixed generic
// direction w. Every view has a symmetric image in that part; with a margin at least the
// grid's covering radius, some grid view near that image is kept.
bool InSymmetryDomain(const Model& model, const Eigen::Vector3f& dir_model, float margin_deg);

}  // namespace sh
