// A peer of the texture path built from OpenCV's parts, for the bench (host only; the firmware
// never links OpenCV): SIFT features learnt on the same training views as the feature database
// (rectified faces and their tilts), FLANN kd-tree matching with Lowe's ratio test, a RANSAC
// homography per printed face, then the pose of each model by solvePnP over its faces'
// correspondences, refined by stereo: the inlier features matched into the right image (SIFT,
// along the epipolar line), triangulated, and the model points fitted to them (Umeyama).
#pragma once

#include <memory>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/image.hpp"
#include "tools/tablegen/feature_db_builder.hpp"

namespace sh::tools {

struct PeerObject {
  int model = 0;  // index into the models the peer learnt
  RigidTransform cam_T_model;
  int matches = 0;        // 2-D correspondences of its faces (homography inliers)
  int stereo_points = 0;  // triangulated points used by the final fit (0: solvePnP pose)
};

struct PeerTimings {
  float features_ms = 0;    // SIFT in both images
  float matching_ms = 0;    // FLANN against the learnt features
  float clustering_ms = 0;  // RANSAC homographies
  float stereo_ms = 0;      // solvePnP, right-image matching, triangulation, fit
  float total_ms = 0;
};

class OpenCvTexturePeer {
 public:
  OpenCvTexturePeer();
  ~OpenCvTexturePeer();
  // Learns SIFT features on every printed face's training views.
  Status Learn(const std::vector<TexturedModel>& models, const FeatureDbBuildOptions& options);
  size_t learnt_features() const;
  // Grey images of the calibration's size.
  Status Process(const StereoCalibration& calib, ConstGrayView left, ConstGrayView right,
                 std::vector<PeerObject>* objects, PeerTimings* time);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sh::tools
