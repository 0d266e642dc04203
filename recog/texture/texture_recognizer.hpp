// Recognition and 6-D localisation of printed models in one stereo frame (seed 001, section
// V), against a feature database:
//
//  1. features of the left image (the database's extraction settings);
//  2. matching: each feature's nearest learnt descriptors by kd-tree best-bin-first, kept when
//     the nearest is clearly closer than the nearest of another physical point (Lowe's ratio);
//  3. 2-D Hough voting per printed face, clusters at the maxima (face_hough.hpp);
//  4. per cluster: affine fit with outlier removal, final homography, accepted with >= 5
//     correspondences and a mean error below 2 px (planar_fit.hpp); several instances of one
//     face are found as separate clusters;
//  5. per face found: Shi-Tomasi points in its contour, ZNCC along the epipolar curve, RANSAC
//     plane, the face's corner rays cut with the plane, Horn's absolute orientation against the
//     model's corners (plane_stereo.hpp, absolute_orientation.hpp);
//  6. faces whose poses agree become one object; its pose is refined with every consistent
//     correspondence of both images (texture_pose.hpp) and verified against the print in both
//     images with the objects accepted before it as occluders (print_verify.hpp).
//
// Statically sized (about 60 MiB with the feature extractor): keep one in static storage or
// allocate it once at start-up; Process() never allocates.
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/image.hpp"
#include "recog/texture/face_hough.hpp"
#include "recog/texture/feature_extractor.hpp"
#include "recog/texture/kd_tree.hpp"
#include "recog/texture/parallel.hpp"
#include "recog/texture/planar_fit.hpp"
#include "recog/texture/plane_stereo.hpp"
#include "recog/texture/print_verify.hpp"
#include "recog/texture/texture_pose.hpp"
#include "tables/feature_db_view.hpp"

namespace sh::texture {

inline constexpr size_t kMaxFaceDetections = 64;
inline constexpr size_t kMaxTextureObjects = 32;
inline constexpr int kMatchNeighbours = 6;

struct MatchConfig {
  int max_checks = 128;        // descriptors compared per query (best-bin-first)
  float ratio = 0.8f;          // nearest / nearest other physical point, distances
  float same_point_mm = 3.0f;  // learnt features this close on one face are one physical point
};

struct TextureRecognizerConfig {
  size_t max_keypoints = kMaxTextureKeypoints;
  MatchConfig matching;
  HoughConfig hough;
  PlanarFitConfig planar;
  PlaneStereoConfig stereo;
  PoseRefineConfig refine;
  PrintVerifyConfig verify;
  // Faces of one model whose poses agree within these limits are one object.
  float merge_distance_mm = 15.0f;
  float merge_angle_deg = 10.0f;
  // Objects of any model closer than this (centres) to an accepted one are duplicates.
  float duplicate_distance_mm = 20.0f;
  // Depths (along the optical axis) faces are expected at. With auto_scales, Init sets the
  // Hough scales for the camera and the database's resolution from them (face_hough.hpp,
  // ScalesForCamera); otherwise hough.scales are used as given.
  bool auto_scales = true;
  float min_depth_mm = 300.0f;
  float max_depth_mm = 900.0f;
};

struct TextureObject {
  uint16_t model = 0;  // index into the database's models
  RigidTransform cam_T_model;
  uint16_t faces = 0;            // faces found in 2-D that make up the object
  uint16_t feature_matches = 0;  // correspondences used by the final pose
  uint16_t stereo_points = 0;    // stereo points used by the final pose
  float plane_mean_mm = 0;       // plane fit of its faces (mean over faces of the mean |error|)
  float plane_max_mm = 0;
  float feature_rms_px = 0, stereo_rms_px = 0;
  PrintScore print;
};

// Milliseconds; zero without a clock.
struct TextureTimings {
  float features_ms = 0, matching_ms = 0, clustering_ms = 0, stereo_ms = 0, verify_ms = 0,
        total_ms = 0;
};

struct TextureStats {
  uint32_t keypoints = 0;
  uint32_t matches = 0;
  uint32_t votes = 0;
  uint32_t clusters = 0;
  uint32_t faces_2d = 0;    // accepted by the planar fit
  uint32_t faces_3d = 0;    // with a stereo plane and a pose
  uint32_t hypotheses = 0;  // objects after merging faces
  uint32_t rejected = 0;    // by verification
  uint64_t descriptors_compared = 0;
};

// What happened to each face found in 2-D and to each object hypothesis (diagnostics: the
// bench explains misses with them).
struct TextureFaceInfo {
  uint16_t face = 0;           // database face
  uint16_t matches = 0;        // after the planar fit
  float mean_error_px = 0;     // of the homography
  uint16_t stereo_points = 0;  // matched in the right image
  uint16_t plane_inliers = 0;
  bool posed = false;
  // The face's contour in the left image by the homography (ideal pixels): the 2-D
  // localisation of the paper's figure 6.
  uint8_t n_corners = 0;
  float corners_px[kMaxTexturedFaceCorners][2] = {};
};

enum class HypothesisOutcome : uint8_t { kAccepted, kDuplicate, kPrintRejected, kObjectsFull };

struct TextureHypothesisInfo {
  uint16_t model = 0;
  uint16_t faces = 0;
  RigidTransform cam_T_model;
  PrintScore print;
  HypothesisOutcome outcome = HypothesisOutcome::kAccepted;
};

struct TextureResult {
  Vector<TextureObject, kMaxTextureObjects> objects;
  Vector<TextureFaceInfo, kMaxFaceDetections> faces;
  Vector<TextureHypothesisInfo, kMaxFaceDetections> hypotheses;
  TextureStats stats;
  TextureTimings time;
};

// The per-frame arrays are scratch written before they are read: not zeroed by design.
class TextureRecognizer {  // NOLINT(cppcoreguidelines-pro-type-member-init)
 public:
  using ClockFn = int64_t (*)();

  // The database must outlive the recogniser. Fails when its extraction settings are invalid
  // or the calibration's image size exceeds the static buffers.
  // `parallel` spreads the features, matching and stereo over threads (the caller's pool);
  // results do not depend on it.
  Status Init(const StereoCalibration& calib, const FeatureDbView& db,
              const TextureRecognizerConfig& config, ClockFn now_ns = nullptr,
              const ParallelFor& parallel = {});

  // Grey images of the calibration's size. On error the result is empty and the Status names
  // the problem.
  Status Process(ConstGrayView left, ConstGrayView right, TextureResult* out);

  const TextureFeatures& left_features() const { return features_; }
  const FeatureDbView& db() const { return db_; }
  const TextureRecognizerConfig& config() const { return config_; }

 private:
  struct FaceDetection {
    uint16_t face = 0;
    PlanarFit fit;
    uint16_t first_match = 0, n_matches = 0;  // into planar_ (inliers)
    uint16_t n_stereo = 0;                    // plane inliers, first in its scratch's stereo points
    bool posed = false;
    RigidTransform cam_T_model;
    PlaneFitStats plane;
  };

  void MatchFeatures();
  void FindFaces();
  void LocateFace(size_t index);
  void MatchBand(int band);
  void AssembleObjects(TextureResult* out);
  float MsSince(int64_t start_ns) const;

  bool initialised_ = false;
  StereoCalibration calib_;
  FeatureDbView db_;
  TextureRecognizerConfig config_;
  TextureFeatureConfig extraction_;
  ClockFn now_ns_ = nullptr;
  ParallelFor parallel_;

  TextureFeatureExtractor extractor_;
  TextureFeatures features_;
  Eigen::Vector2f ideal_px_[kMaxTextureKeypoints];  // undistorted keypoint positions
  KdSearcher searchers_[kParallelBands];            // one per band of keypoints
  uint32_t match_of_[kMaxTextureKeypoints] = {};    // learnt feature per keypoint, or none
  struct Match {
    uint16_t keypoint;
    uint32_t feature;
  };
  Vector<Match, kMaxTextureMatches> matches_;
  HoughInput hough_inputs_[kMaxTextureMatches];
  FaceHough hough_;
  Vector<HoughCluster, kMaxHoughClusters> clusters_;
  Vector<uint16_t, 9 * kMaxTextureMatches> cluster_matches_;
  bool keypoint_used_[kMaxTextureKeypoints] = {};
  Vector<PlanarMatch, kMaxTextureMatches> cluster_planar_;
  Vector<PlanarMatch, 4 * kMaxTextureMatches> planar_;  // inliers of all detections
  Vector<FaceDetection, kMaxFaceDetections> detections_;
  PlaneStereoMatcher stereo_matcher_;
  // Per face detection (they are located in parallel): its Shi-Tomasi points and stereo points.
  struct FaceScratch {
    Vector<Eigen::Vector2f, kMaxFaceStereoPoints> contour;
    Vector<StereoPoint, kMaxFaceStereoPoints> stereo;
  };
  FaceScratch face_scratch_[kMaxFaceDetections];
  PoseFeatureObservation feature_obs_[kMaxPoseObservations];
  PoseStereoObservation stereo_obs_[kMaxPoseObservations];
  TexturePoseRefiner refiner_;
  Vector<TextureObject, kMaxFaceDetections> candidates_;
  PrintVerifier verifier_;
  ConstGrayView left_{}, right_{};
};

}  // namespace sh::texture
