// Offline build of the shape path's view database (recog/shape/view_database.hpp): views of
// every colour model over the viewing sphere and the in-plane rotation, their size-normalised
// windows, a PCA basis fitted to them, and each view's coefficients.
//
// Orientation sampling: viewing directions on a Fibonacci sphere and in-plane angles, both at
// `view_spacing_deg`, so orientations fill the rotation group uniformly; of each class of
// orientations that a model's symmetry maps onto one another only the member nearest a fixed
// generic reference rotation is kept (a Dirichlet fundamental domain), so a model with a
// symmetry group of order g keeps about 1/g of the samples at the same spacing.
//
// Host only (allocates freely, runs for seconds to minutes).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"

namespace sh {

struct ShapeModelInput {
  Model model;
  float kd[3] = {0, 0, 0};  // MTL diffuse colour, linear 0..1
};

struct ShapeViewBuildOptions {
  float view_spacing_deg = 10.0f;
  int n_components = 100;
  // The camera the views are rendered with: the model origin on its axis at this distance.
  float render_focal_px = 1136.0f;
  float render_distance_mm = 450.0f;
  // Views the PCA basis is fitted to (a deterministic subset when there are more).
  int pca_views = 6000;
  int power_iterations = 3;  // of the randomised PCA
};

struct ShapeModelViewCount {
  std::string model;
  uint32_t views = 0;
  uint32_t symmetries = 0;
};

struct ShapeViewBuildReport {
  std::vector<ShapeModelViewCount> per_model;
  uint32_t views = 0;
  float explained_energy = 0;  // share of the fitted views' variance the components keep
};

// Fills each model's symmetry group (Model::symmetries) on the way.
Result<std::vector<uint8_t>> BuildShapeViewBlob(std::vector<ShapeModelInput> models,
                                                const ShapeViewBuildOptions& options,
                                                ShapeViewBuildReport* report = nullptr);

}  // namespace sh
