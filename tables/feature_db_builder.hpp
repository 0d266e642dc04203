// Offline learning of the texture feature database (seed 001, section V; the paper's training
// images, made from the models' artwork instead of photographs):
//
// For every printed face: the texture rectified to a fronto-parallel view at feature_px_per_mm
// (bilinear sampling of the artwork through the face's UV map), and synthetic views of it
// tilted by the affine compressions `tilts` in `tilt_directions` directions (the foreshortening
// of a face seen obliquely, which the descriptor tolerates only up to about 30 degrees). The
// feature extractor of the board runs on every view; each feature whose descriptor window lies
// on the face keeps its view position and orientation (for the Hough vote) and its 3-D point on
// the model. A kd-tree over all descriptors and the faces' grey textures at texture_px_per_mm
// (for verification) complete the blob.
//
// Runs on the host; allocates freely; never on the per-frame path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/texture/feature_extractor.hpp"
#include "tables/textured_model_files.hpp"

namespace sh {

struct FeatureDbBuildOptions {
  float feature_px_per_mm = 4.0f;
  float texture_px_per_mm = 2.0f;
  // Compression factors 1 / cos(tilt angle) of the synthetic views; 1.6 is about 51 degrees.
  std::vector<float> tilts = {1.6f};
  int tilt_directions = 4;  // directions per tilt, evenly over 180 degrees
  texture::TextureFeatureConfig features;
  uint32_t leaf_size = 8;  // descriptors per kd-tree leaf (at most)
};

struct FeatureDbFaceReport {
  std::string model;
  int model_face = 0;
  int texel_width = 0, texel_height = 0;
  uint32_t features = 0;  // all views
};

struct FeatureDbBuildReport {
  std::vector<FeatureDbFaceReport> faces;
  uint32_t views = 0;
  uint32_t features = 0;
  uint32_t nodes = 0;
  uint32_t tree_depth = 0;
};

// Builds the blob from the textured faces of `models` (untextured faces are left out; models
// without any printed face are refused).
Result<std::vector<uint8_t>> BuildFeatureDb(const std::vector<TexturedModel>& models,
                                            const FeatureDbBuildOptions& options,
                                            FeatureDbBuildReport* report = nullptr);

}  // namespace sh
