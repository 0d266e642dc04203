// The shape path of seed 001 (section IV) for single-colour parts, end to end on one stereo
// pair of colour frames:
//   1. colour segmentation of both images into regions (ColourSegmentation);
//   2. left/right region pairs by epipolar geometry (PairRegions);
//   3. per pair, the size-normalised window of each region, projected into PCA space, gives the
//      nearest views of the models of its colour whose size fits the region (the view's extent
//      in millimetres against the region's, at the triangulated depth): model and orientation;
//   4. position from the triangulated centroids with the corrective iterations: the silhouette
//      predicted at the current pose moves the centroid by an offset, which is removed, and the
//      orientation follows the new viewing ray;
//   5. refinement on the silhouette and crease edges in both images (ShapeRefiner);
//   6. verification in both images: enough of the projected edges confirmed, and the predicted
//      silhouette covering part-coloured pixels, not the table. The best verified hypothesis of
//      a region is accepted; it hides what lies behind it and explains its pixels, so a region
//      of two touching parts keeps an unexplained remainder that is tried again as a region of
//      its own.
// Results are RecognizedObjects like the polyhedral path's, model ids offset by the caller's
// model_id_offset (the shape models follow the hash tables' models in one model set).
//
// Statically allocated (about 12 MB); Process() never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/image/frame.hpp"
#include "recog/shape/colour_classes.hpp"
#include "recog/shape/region_pairs.hpp"
#include "recog/shape/segmentation.hpp"
#include "recog/shape/shape_refine.hpp"
#include "recog/shape/shape_window.hpp"
#include "recog/shape/silhouette.hpp"
#include "recog/shape/view_database.hpp"

namespace sh {

inline constexpr size_t kMaxShapeCandidates = 16;  // views tried per region pair (both images)

// The two stages of refinement: a few iterations over sparse samples with a wide search, then
// the full one from where that ended.
ShapeRefineConfig CoarseRefine();
ShapeRefineConfig FineRefine();

struct ShapeConfig {
  SegmentConfig segment;
  RegionPairConfig pairs;
  // Every candidate view gets a short, coarse refinement; the best `fine_hypotheses` of them by
  // the share of edges found then get the full one, and are verified.
  ShapeRefineConfig coarse = CoarseRefine();
  ShapeRefineConfig refine = FineRefine();
  int fine_hypotheses = 2;
  // Nearest views taken from each image's window, after the size check and dropping views
  // within diverse_deg of a better one of the same model.
  int views_per_image = 3;
  float diverse_deg = 20.0f;
  // A view's extent (box width and height, mm at the part's depth) must lie within this factor
  // of the region's.
  float max_extent_ratio = 1.3f;
  int corrective_iterations = 3;
  // Verification, in each image: confirmed share of the edge samples, and at most this share of
  // the predicted silhouette showing no part colour (the table).
  float min_edge_score = 0.55f;
  float max_background_share = 0.12f;
  // A pair whose left or right region is already this much explained is skipped.
  float explained_share = 0.6f;
};

Status CheckShapeConfig(const ShapeConfig& config);

struct ShapeTimings {
  float segment_ms = 0, search_ms = 0, refine_ms = 0, verify_ms = 0, total_ms = 0;
};

struct ShapeStats {
  uint32_t regions[2] = {0, 0};
  uint32_t pairs = 0;
  uint32_t hypotheses = 0;  // refined
  uint32_t verified = 0;
  bool runs_truncated = false, regions_truncated = false, pairs_truncated = false;
  bool objects_full = false;
  ShapeTimings time;
};

class ShapeRecognizer {
 public:
  using ClockFn = int64_t (*)();

  // The view database must outlive the recogniser. Fails when the database's colours cannot be
  // segmented (DeriveColourClasses) or the configuration is out of range.
  Status Init(const StereoCalibration& calib, const ShapeViewsView& views,
              const ShapeConfig& config, uint16_t model_id_offset, ClockFn now_ns = nullptr);

  // Recognises the colour parts of one stereo pair; appends to `out` (objects other paths
  // found earlier in the frame are kept and act as occluders).
  Status Process(const FrameView& left, const FrameView& right, Vector<RecognizedObject>& out,
                 ShapeStats* stats);

  const ColourSegmentation& segmentation(int camera) const { return segmentation_[camera]; }
  const ColourClassifier& classifier() const { return classifier_; }
  const ShapeViewsView& views() const { return views_; }
  uint8_t colour_of_model(uint32_t m) const { return colour_of_model_[m]; }

 private:
  struct Candidate {
    uint16_t model;
    Eigen::Matrix3f cam_R_model;  // from the view, at the pair's centroid
  };
  struct Verdict {
    bool accepted = false;
    float evidence = 0;
    float edge_score[2] = {0, 0};
  };

  void Candidates(const RegionPair& pair, Vector<Candidate>& out);
  bool RegionWindow(int camera, const ColourRegion& region, ShapeWindow* window);
  void InitialPose(const RegionPair& pair, PosedModel* object);
  Verdict Evaluate(const PosedModel& object, uint8_t colour, const ShapeRefineResult& fit);
  float ExplainedShare(int camera, const ColourRegion& region) const;
  void MarkExplained(const PosedModel& object);
  float MsSince(int64_t start) const;

  bool initialised_ = false;
  StereoCalibration calib_;
  ShapeViewsView views_;
  ShapeConfig config_;
  uint16_t model_id_offset_ = 0;
  ClockFn now_ns_ = nullptr;
  ColourClassifier classifier_;
  uint8_t colour_of_model_[kMaxShapeModels] = {};

  ColourSegmentation segmentation_[2];
  Vector<RegionPair, kMaxRegionPairs> pairs_;
  ShapeWindowScratch window_scratch_;
  SilhouetteScratch silhouette_scratch_;
  uint8_t region_mask_[kMaxImagePixels];
  uint8_t explained_[2][kMaxImagePixels];  // pixels covered by accepted objects' silhouettes
  ShapeRefiner refiner_;
  // Occluders: the objects accepted in this frame (theirs and other paths').
  PosedModel occluders_[kMaxOccluders];
  size_t n_occluders_ = 0;
  ShapeImages images_;
};

}  // namespace sh
