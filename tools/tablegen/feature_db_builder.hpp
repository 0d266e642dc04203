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

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/textured_model.hpp"
#include "recog/texture/feature_extractor.hpp"
#include "tables/feature_db_format.hpp"

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

// One training image of a printed face: the rectified face (tilt 0) or a tilted view of it.
struct LearningView {
  int tilt = 0;  // 0: frontal; k: options.tilts[k - 1]
  GreyImage image;
  Eigen::Matrix2f view_from_face = Eigen::Matrix2f::Identity();  // view pixels per face mm
  Eigen::Vector2f view_of_centre = Eigen::Vector2f::Zero();      // view pixel of the face centre
  Eigen::Vector2f centre_ab_mm = Eigen::Vector2f::Zero();        // face centre, face frame
  Eigen::Vector2f polygon_px[kMaxTexturedFaceCorners];           // the face in the view
  int n_polygon = 0;

  // Whether view pixel p lies at least margin_px inside the face.
  bool Inside(const Eigen::Vector2f& p, float margin_px) const;
  // The model point (millimetres) at view pixel p.
  Eigen::Vector3f ModelPoint(const TexturedFace& face, const Eigen::Vector2f& p) const;
};

// Texels of the artwork's mean grey around each rectified face in its views, so that keypoints
// near the face's edge exist at the coarse pyramid levels as they do in a scene (where the face
// is embedded in a larger image): without it a level's image border (the descriptor window)
// kept the coarse levels of a small face to its middle.
int ViewMarginPx(const FeatureDbBuildOptions& options);

// A printed face's frame (model index 0; the caller sets it), its verification texture and its
// training images, as the database learns them.
struct FaceLearning {
  TexturedFace face{};
  GreyImage texture;  // at texture_px_per_mm
  std::vector<LearningView> views;
};
Result<FaceLearning> LearnFace(const TexturedModel& model, int face,
                               const FeatureDbBuildOptions& options);

// Builds the blob from the textured faces of `models` (untextured faces are left out; models
// without any printed face are refused).
Result<std::vector<uint8_t>> BuildFeatureDb(const std::vector<TexturedModel>& models,
                                            const FeatureDbBuildOptions& options,
                                            FeatureDbBuildReport* report = nullptr);

}  // namespace sh
