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
// Steps 3 to 6 of one seed spread their candidates over the caller's threads (SetParallel); the
// results do not depend on how many there are.
// Results are RecognizedObjects like the polyhedral path's, model ids offset by the caller's
// model_id_offset (the shape models follow the hash tables' models in one model set).
//
// Statically allocated (about 32 MB); Process() never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/parallel_for.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/image/frame.hpp"
#include "recog/shape/blob_split.hpp"
#include "recog/shape/colour_classes.hpp"
#include "recog/shape/near_symmetry.hpp"
#include "recog/shape/region_pairs.hpp"
#include "recog/shape/segmentation.hpp"
#include "recog/shape/shape_refine.hpp"
#include "recog/shape/shape_window.hpp"
#include "recog/shape/silhouette.hpp"
#include "recog/shape/view_database.hpp"

namespace sh {

inline constexpr size_t kMaxShapeCandidates = 24;  // views tried per seed (both images)
// Blobs per image: the segmentation's regions, then the unexplained remainders and neck splits
// of the rounds after it (ids are one byte: at most 255).
inline constexpr size_t kMaxBlobs = 192;
inline constexpr int kShapeRounds = 3;
// Threads that refine one seed's candidates at once (ShapeRecognizer::SetParallel); each has its
// own refiner, silhouette raster and window rows (about 1.7 MiB: pages a thread never uses stay
// unbacked).
inline constexpr int kMaxShapeThreads = 4;

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
  // Nearest views taken from each image's window for each model of the blob's colour, after
  // the size check and dropping views within diverse_deg of a better one.
  int views_per_image = 3;
  float diverse_deg = 20.0f;
  // A view's extent (box width and height, mm at the part's depth) must lie within this factor
  // of the region's.
  float max_extent_ratio = 1.3f;
  int corrective_iterations = 3;
  // The corrective iterations stop early once one moves the part by less than this (0: all
  // run). From centroids the moves shrink fast (2.7 mm, then 0.06 mm, then 0.02 mm, medians on
  // the recorded colour set): after a move under 0.5 mm the next is hundredths of a millimetre,
  // far inside the coarse refinement's reach. Placements in a merger can still jump, and keep
  // iterating.
  float corrective_converged_mm = 0.5f;
  // A stereo seed's blob larger than a candidate's predicted silhouette by more than this share
  // (silhouette area under merger_area_ratio times the blob's) merges the part with another of
  // its colour: when none of a seed's first fine starts verified, its candidates are started
  // again where their silhouettes fit the blobs best (silhouette_placement.hpp; the corrective
  // iterations move them there instead of matching centroids), coarse and fine stages as
  // before. 0: never.
  float merger_area_ratio = 0.7f;
  // Parts with a near symmetry (near_symmetry.hpp: the bracket) are refined half a turn from
  // where they were found too, and the pose the images explain better is kept.
  bool near_symmetries = true;
  // A winner with weak edge evidence (under weak_edge_score in either image) may be a local
  // minimum near the truth: it is refined again from its pose turned by +-restart_deg about each
  // of its model's axes, and the verified pose with the most evidence is kept (0: off).
  float weak_edge_score = 0.7f;
  float restart_deg = 10.0f;
  // A seed none of whose fine starts verified gets a second pass: up to second_pass_starts more
  // coarse results refined, then, if still none verifies, the unverified result with the most
  // edges confirmed (at least second_pass_min_score in both images) restarted as above.
  bool second_pass = true;
  int second_pass_starts = 2;
  float second_pass_min_score = 0.35f;
  // Verification, in each image: confirmed share of the edge samples, and at most this share of
  // the predicted silhouette showing no part colour (the table).
  float min_edge_score = 0.55f;
  float max_background_share = 0.12f;
  // A blob already this much explained by accepted parts is not tried again.
  float explained_share = 0.6f;
  // Remainders are split where two parts meet at a neck narrower than this share of the
  // smaller part's inscribed radius (blob_split.hpp).
  float neck_ratio = 0.6f;
  // A blob tried whole and neither explained nor split is opened by a disc of this share of its
  // largest inscribed radius (blob_split.hpp), and what stays is tried.
  float opening_ratio = 0.6f;
  // In the last round, what is still unexplained is split at every saddle of the distance
  // transform lower than this share of the smaller peak (1: a full watershed; the pieces seed
  // hypotheses whose refinement uses the whole image, so a piece need not be a whole part).
  float last_split_ratio = 1.0f;
  // Rounds of blobs: the regions, then remainders and splits (at most kShapeRounds).
  int rounds = 2;
};

Status CheckShapeConfig(const ShapeConfig& config);

struct ShapeTimings {
  float segment_ms = 0, search_ms = 0, refine_ms = 0, verify_ms = 0, total_ms = 0;
};

struct ShapeStats {
  uint32_t regions[2] = {0, 0};
  uint32_t blobs[2] = {0, 0};  // regions, remainders and splits
  uint32_t pairs = 0;
  uint32_t mono_seeds = 0;  // blobs tried from one image (no partner verified)
  uint32_t hypotheses = 0;  // refined
  uint32_t verified = 0;
  // Accepted parts with a near symmetry refined half a turn away too (near_symmetry.hpp), and
  // how often that pose replaced the first.
  uint32_t turned = 0, turned_kept = 0;
  // Weak winners refined again from turned starts, and how often one of those replaced them.
  uint32_t restarted = 0, restart_kept = 0;
  // Seeds with no verified start whose weak result (the unverified one with the most edges
  // confirmed) was refined from its near symmetries' turned poses, and how often one verified.
  uint32_t weak_turned = 0, weak_turned_kept = 0;
  // Seeds with no verified start whose candidates were started again placed in a blob that
  // merges two parts (ShapeConfig::merger_area_ratio), and how often one of those verified.
  uint32_t merger_seeds = 0, merger_found = 0;
  bool runs_truncated = false, regions_truncated = false, pairs_truncated = false;
  bool blobs_full = false;
  bool objects_full = false;
  ShapeTimings time;
};

// Its scratch members are written before they are read: initialising them would make every page
// of the workspace resident (docs/memory.md).
// NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init)
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

  // Refinement of a seed's candidates on `parallel`'s threads, at most `threads` (capped at
  // kMaxShapeThreads) at once; a ParallelFor without a pool, or threads 1, keeps it on the
  // caller. Each candidate writes its own slot and the slots are read in order, so the objects
  // are those of one thread, bit for bit.
  void SetParallel(const ParallelFor& parallel, int threads);

  // What the last frame shows of a part at a given pose (diagnostics: why a part was missed):
  // the fine refinement from `object` (which receives the refined pose) and the verification's
  // verdict there, with `occluders` hiding it.
  struct Assessment {
    bool refined = false;  // refinement found enough edges to run
    bool accepted = false;
    float edge_score[2] = {0, 0};
    float background_share[2] = {1, 1};
  };
  Status Assess(PosedModel* object, const PosedModel* occluders, size_t n_occluders,
                Assessment* out) const;

  const ColourSegmentation& segmentation(int camera) const { return segmentation_[camera]; }
  const ColourClassifier& classifier() const { return classifier_; }
  const ShapeViewsView& views() const { return views_; }
  uint8_t colour_of_model(uint32_t m) const { return colour_of_model_[m]; }

 private:
  struct Candidate {
    uint16_t model;
    uint32_t view;
    int camera;                   // the image whose window gave it
    Eigen::Matrix3f cam_R_model;  // left camera frame, at the seed's centre
  };
  struct Verdict {
    bool accepted = false;
    float evidence = 0;
    float edge_score[2] = {0, 0};
    float background_share[2] = {1, 1};
  };
  // What one thread writes: its refiner's samples, a silhouette raster (a blob's mask while
  // the windows are computed) and a window's rows (written before read, like the class's other
  // scratch).
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init)
  struct ThreadScratch {
    ShapeRefiner refiner;
    SilhouetteScratch silhouette;
    ShapeWindowScratch window;
  };
  // Time one refinement and its verification took (the stage times share a parallel stage's
  // wall-clock time in these proportions).
  struct StageNs {
    int64_t refine = 0, verify = 0;
  };
  // Where a part may be: one blob in each image (stereo), or one blob in one image.
  struct Seed {
    int blob[2] = {-1, -1};  // indices into blobs_[camera], -1: none
    bool stereo = false;
    Eigen::Vector3f centroid_mm = Eigen::Vector3f::Zero();  // triangulated (stereo)
    float surface_mm = 0;  // mono: depth of the blob's surface (BlobDepth), 0 unknown
    // mono, surface unknown: depth of the stereo pair the blob or its parent was part of
    float pair_depth_mm = 0;
  };

  void ResetBlobs();
  bool AddBlob(int camera, const ColourRegion& blob, uint8_t round, const uint8_t* mask,
               int mask_stride);
  ConstGrayView BlobIds(int camera) const {
    return {blob_ids_[camera], segmentation_[camera].width(), segmentation_[camera].height(),
            segmentation_[camera].width()};
  }
  bool BlobWindow(int camera, const ColourRegion& blob, ThreadScratch& scratch,
                  ShapeWindow* window) const;
  void Candidates(const Seed& seed, Vector<Candidate>& out);
  // The shift that places `silhouette` where it fits a blob that merges its part with another
  // (the blob larger than it by config_.merger_area_ratio); false: not a merger, or no fit.
  bool PlaceInMerger(int camera, int blob_index, const SilhouetteMask& silhouette,
                     Eigen::Vector2d* shift) const;
  bool InitialPoseStereo(const Seed& seed, bool place, SilhouetteScratch& scratch,
                         PosedModel* object) const;
  bool InitialPoseMono(const Seed& seed, const Candidate& c, bool place, SilhouetteScratch& scratch,
                       PosedModel* object) const;
  // Depth (z in `camera`) of a blob's surface by matching its pixels along the epipolar line in
  // the other image: the colours a blob shows (its faces' shading and the creases between them)
  // are seen again there, shifted by the disparity of its depth. 0 when nothing matches.
  float BlobDepth(int camera, const ColourRegion& blob) const;
  // Refines the candidates, verifies the best and accepts the winner; true if one was accepted.
  bool TrySeed(const Seed& seed, Vector<RecognizedObject>& out, ShapeStats& st);
  // `found` turned by each near symmetry of its model (near_symmetry.hpp) into turned[0..n);
  // returns n (at most kMaxNearSymmetries).
  int TurnedPoses(const PosedModel& found, PosedModel* turned) const;
  // A weak winner refined again from turned starts (ShapeConfig::restart_deg); replaces *best
  // and *verdict when a start verifies with more evidence.
  void RestartWeak(uint8_t colour, PosedModel* best, Verdict* verdict, ShapeStats& st);
  // The fine refinement and verification of n starts (on the worker threads): the verified one
  // with the most evidence replaces *best when it has more, the unverified one with the most
  // edges confirmed (in its weaker image) replaces *weak likewise.
  void RefineStarts(uint8_t colour, const PosedModel* starts, size_t n, PosedModel* best,
                    Verdict* best_verdict, PosedModel* weak, Verdict* weak_verdict, ShapeStats& st);
  Verdict Evaluate(const PosedModel& object, uint8_t colour, const ShapeRefineResult& fit,
                   SilhouetteScratch& scratch) const;
  // The fine refinement of *object, then Evaluate(); false when refinement fails.
  bool RefineAndEvaluate(uint8_t colour, ThreadScratch& scratch, PosedModel* object,
                         Verdict* verdict, StageNs* ns) const;
  // Calls fn(slot, k) for every k in [0, n) on up to threads_ slots (a slot: one thread and its
  // ThreadScratch), each slot taking the next k not yet taken.
  template <typename Fn>
  void Spread(int n, Fn&& fn) const;
  void AddStageTimes(int64_t wall_ns, const StageNs& sum);
  float ExplainedShare(int camera, const ColourRegion& blob) const;
  void MarkExplained(const PosedModel& object);
  // The unexplained pixels of this round's blobs, split into parts, as next round's blobs.
  int DeriveBlobs(int camera, uint8_t round, ShapeStats& st);
  float MsSince(int64_t start) const;
  int64_t Now() const { return now_ns_ ? now_ns_() : 0; }

  bool initialised_ = false;
  StereoCalibration calib_;
  ShapeViewsView views_;
  ShapeConfig config_;
  uint16_t model_id_offset_ = 0;
  ClockFn now_ns_ = nullptr;
  ColourClassifier classifier_;
  uint8_t colour_of_model_[kMaxShapeModels] = {};
  NearSymmetries near_[kMaxShapeModels];

  ColourSegmentation segmentation_[2];
  Vector<RegionPair, kMaxRegionPairs> pairs_;
  // Blobs of each image: a ColourRegion each (its runs unused), their pixels by id in
  // blob_ids_ (id = index + 1), the round that made them.
  Vector<ColourRegion, kMaxBlobs> blobs_[2];
  uint8_t blob_round_[2][kMaxBlobs] = {};
  // Depth (z in its camera) of the pair a blob, or its parent, was triangulated in; 0: unknown.
  float blob_depth_[2][kMaxBlobs] = {};
  uint8_t blob_ids_[2][kMaxImagePixels];
  MaskPartsScratch parts_scratch_;
  uint8_t part_labels_[kMaxSplitPixels];
  int64_t search_ns_ = 0, refine_ns_ = 0, verify_ns_ = 0;
  ShapeWindow windows_[2];  // a seed's window in each image
  uint8_t region_mask_[kMaxImagePixels];
  uint8_t explained_[2][kMaxImagePixels];  // pixels covered by accepted objects' silhouettes
  // Per refining thread; [0] is the calling thread's, also of the const diagnostics.
  mutable ThreadScratch scratch_[kMaxShapeThreads];
  ParallelFor parallel_;
  int threads_ = 1;
  // Occluders: the objects accepted in this frame (theirs and other paths').
  PosedModel occluders_[kMaxOccluders];
  size_t n_occluders_ = 0;
  ShapeImages images_;
};

}  // namespace sh
