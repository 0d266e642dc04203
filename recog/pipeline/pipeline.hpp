// The whole recognition pipeline of one stereo frame (thesis fig. 4.1): per-image features,
// sloppy stereo, 3-D geometric hashing with pose refinement, and verification against the edge
// pixels of both images. Init sizes the image buffers for the calibration's image size (one
// allocation per workspace, at start-up: docs/memory.md); Process() never allocates.
#pragma once

#include <atomic>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/image/features.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"
#include "recog/mono/mono_recognizer.hpp"
#include "recog/pipeline/edge_map_verifier.hpp"
#include "recog/pipeline/hidden_mask.hpp"
#include "recog/pipeline/model_set.hpp"
#include "recog/pipeline/table_carry.hpp"
#include "recog/pipeline/table_estimate.hpp"
#include "recog/pipeline/worker_pool.hpp"
#include "recog/scene/scene.hpp"
#include "recog/shape/shape_recognizer.hpp"
#include "recog/stereo/sloppy_stereo.hpp"
#include "recog/stereo/stereo_features.hpp"
#include "recog/verify/edge_refine.hpp"
#include "recog/verify/verify.hpp"
#include "tables/table_view.hpp"

namespace sh {

// The one-image rescue after the stereo search (Pipeline::LendRescue): the monocular recogniser
// searches the left image's features that the accepted objects do not explain, and each object
// it finds is accepted only if the stereo verifier confirms it in both images at that pose, it
// interpenetrates no accepted object and it rests plausibly (on the frame's table when there is
// one, else its centre within the working volume). Objects whose edges stereo loses (edges near
// the epipolar direction, low contrast) have little 3-D support but verify in both images.
struct RescueConfig {
  bool enabled = true;
  // The gate: the rescue runs only when at least this many left-image corners lie outside the
  // accepted objects' silhouettes (grown by margin_px, with discs of corner_radius_px around
  // their projected corners), the hidden objects' and over the table.
  int min_free_corners = 6;
  // The search sees the same: an accepted object's own corners, which its pose error and the
  // detector's blur put a pixel or two off its outline, leave it with the discs, while the
  // corners of its neighbours next to its outline (objects in contact, in front of one another)
  // stay. A margin as wide as the discs hides those too: over sixteen polyhedral sets (shared
  // and own, clean and factory floor) margin 4 px without discs found 7 objects fewer, 5 of them
  // 40 % visible or more, with as many false alarms.
  float margin_px = 0.0f;
  float corner_radius_px = 4.0f;
  // Scene bases the one-image search may try (its own max_fruitless_bases ends it earlier).
  uint32_t max_scene_bases = 400;
  // With a table: the lowest corner at most this far over the table top (the one-image pose
  // rests on the table; a pose that floats is not the object's).
  float max_above_table_mm = 10.0f;
  // Then the right image the same way, with what the left one added among the known objects:
  // each camera loses other edges to low contrast and to the other objects, so an object whose
  // corners the left image lacks may show them on the right (the recogniser is set to the right
  // camera for that search and set back).
  bool right_image = true;
  // A one-image pose is least certain in depth, which the stereo verifier sees as an outline
  // shifted in the other image: each candidate is first fitted to both images' edge pixels (the
  // final edge fit, PipelineConfig::edge_refine_config, with the verifier's occluders:
  // EdgeMapVerifier::FitAndVerify).
  bool edge_fit = true;
};

struct PipelineConfig {
  FeatureConfig features = FeatureConfig::DarkBackground();
  // stereo.volume is the working volume (a box around the table): 3-D features outside it are
  // dropped and 3-D lines are clipped to it. Nothing is derived from the scene.
  SloppyStereoConfig stereo;
  RecognizerConfig recognizer;
  VerifyConfig verify;
  TableConstraint table;
  // Without a known table, the plane the objects found rest on (table_estimate.hpp), used as a
  // given table is (TableEstimateConfig::search_again).
  TableEstimateConfig table_estimate;
  // With the estimate enabled and no table given: the estimated plane confirmed over a few
  // frames and carried to the following ones (table_carry.hpp), each of which then searches once
  // as with a given table. For a fixed cell; off for scenes seen from different poses.
  TableCarryConfig table_carry;
  // Final fit of every accepted pose to the edge pixels of both images (edge_refine.hpp).
  bool edge_refine = true;
  EdgeRefineConfig edge_refine_config;
  // A hypothesis the image verification rejects narrowly is fitted to both images' edge pixels
  // (edge_refine_config) and verified again (edge_map_verifier.hpp; off by default).
  SecondLook second_look;
  // Threads of the pipeline's worker pool, the calling thread included: with two or more the
  // left and right features are extracted in parallel, the search votes on all of them
  // (Recognizer::SetParallel), the colour path refines its candidates on them
  // (ShapeRecognizer::SetParallel) and the final edge fits are spread over them. 0: all online
  // cores.
  int threads = 0;
  // Frames may be RGB (PNG files, a camera that offers only BGR888): the polyhedral path then
  // converts each into a grey image of the calibration's size, 2 W H bytes taken at Init. Off
  // for sources that always hand over a luma plane (grey, NV12, YUV420): no such images, and an
  // RGB frame is refused with an error.
  bool rgb_frames = true;
  // The shape path for colour parts (used when a view database is given and frames are colour).
  ShapeConfig shape;
  // Objects found by another path before the polyhedral one (Process's `hidden`, the printed
  // cartons): their silhouettes, grown by this margin, are hidden from the polyhedral features
  // (corners dropped, edge pixels cleared before line detection and verification). The margin
  // covers the carton's pose error (about 1 px) and the Canny and corner blur (2-3 px).
  float hide_margin_px = 4.0f;
  // The one-image rescue (runs only when a recogniser is lent: Pipeline::LendRescue).
  RescueConfig rescue;

  // Presets for the two kinds of scene (thesis 5.3): the detectors' preset plus recognition and
  // verification settings measured on rendered scenes (docs/pipeline.md).
  static PipelineConfig DarkBackground();
  static PipelineConfig LightBackground();
  // The default: no preset to pick. Detector thresholds measured from each image
  // (FeatureConfig::adaptive), the Canny scale of the light preset, the longer search.
  static PipelineConfig Automatic();
};

// Milliseconds; zero when no clock was given. hashing_ms covers voting and pose refinement
// (recognition minus the verifier's own time), verify_ms the verifier calls, refine_ms the final
// fit to the image edges, so the five stages add up to total_ms up to bookkeeping.
struct PipelineTimings {
  float features_ms = 0, stereo_ms = 0, hashing_ms = 0, verify_ms = 0, refine_ms = 0, total_ms = 0;
  // The table estimate and dropping the features outside the space over it (the second search
  // counts as hashing and verification).
  float table_ms = 0;
  // The one-image rescue (its search and its verifications).
  float rescue_ms = 0;
};

// What the one-image rescue did in a frame.
struct RescueStats {
  bool ran = false;                 // the gate let it run (in either image)
  bool ran_right = false;           // ... in the right image
  uint32_t free_corners = 0;        // left-image corners none of the accepted objects explains
  uint32_t free_corners_right = 0;  // the same in the right image, after the left's search
  uint32_t found = 0;               // objects the one-image search found
  uint32_t refused_rest = 0;        // ... not resting plausibly (table, working volume)
  uint32_t refused_verify = 0;      // ... failing the stereo verifier (both images)
  uint32_t refused_overlap = 0;     // ... interpenetrating an accepted object
  uint32_t edge_fitted = 0;         // candidates whose pose the edge fit moved (edge_fit)
  uint32_t added = 0;               // accepted
  MonoStats search;                 // the left image's search
  MonoStats search_right;           // the right image's
};

// Which table the frame's table check and working volume used.
enum class TableSource : uint8_t {
  kNone = 0,   // no table: the configured working volume only
  kGiven,      // PipelineConfig::table (table.yaml, the firmware's table key, the renderer's)
  kEstimated,  // estimated from this frame's objects (PipelineResult::table_estimate)
  kCarried,    // estimated in earlier frames and carried (PipelineResult::table_carry)
};
const char* TableSourceName(TableSource s);

struct PipelineResult {
  Vector<RecognizedObject, kMaxObjects> objects;  // verify_score = {left, right}
  uint32_t points2d[2] = {0, 0};                  // corners, left and right
  uint32_t lines2d[2] = {0, 0};                   // lines, left and right
  uint32_t points3d = 0, lines3d = 0;
  RecognitionStats recognition;
  PipelineTimings time;
  DetectionChoice detection[2];  // detector settings used on the left and right image
  // Stereo output reached the Scene's capacity (kMaxScenePoints / kMaxSceneLines): recognition
  // ran on the truncated scene.
  bool points3d_truncated = false, lines3d_truncated = false;
  // Verifier calls that returned an error (treated as rejections; normally 0).
  uint32_t verify_errors = 0;
  // Hypotheses rejected for sinking into the table (given or estimated).
  uint32_t below_table = 0;
  // The table used; the estimate (outcome, plane, support) whenever one was made, accepted or
  // not; 3-D features dropped for lying under the estimated table or too far over it (points3d
  // and lines3d count those kept).
  TableSource table_source = TableSource::kNone;
  TableEstimate table_estimate;
  uint32_t table_dropped = 0;
  // The carried plane after this frame (PipelineConfig::table_carry; kSearching when off), and,
  // on a carried frame, how many of the objects found rest on it.
  TableCarry table_carry;
  uint32_t table_resting = 0;
  // The shape path's counts and stage times (zero when it did not run).
  ShapeStats shape;
  // Objects hidden from the polyhedral path (Process's `hidden`): those masked in both images,
  // those not masked in an image (mask full, or not in front of the camera), and per image the
  // corners dropped and edge pixels cleared.
  uint32_t hidden_objects = 0, hidden_not_masked = 0;
  uint32_t masked_corners[2] = {0, 0}, masked_edge_pixels[2] = {0, 0};
  // Of the hidden objects, the colour parts the shape path found in this frame.
  uint32_t hidden_colour_parts = 0;
  // Polyhedral hypotheses rejected, and objects dropped after the edge fit, because their centre
  // lies inside a hidden object (inside_object.hpp): one object, one report.
  uint32_t inside_hidden = 0;
  // Hypotheses that passed the verification on a second look (PipelineConfig::second_look).
  uint32_t second_looks = 0;
  RescueStats rescue;
};

class Pipeline {
 public:
  // Monotonic clock used for the timings and the time budget (no clock: no timings, and only
  // the scene-basis budget applies).
  using ClockFn = int64_t (*)();

  // `table`: hash tables of the polyhedra (may be an empty TableView when `shape_views` holds
  // the whole model set); `shape_views`: view database of the colour parts, or null. Both must
  // outlive the pipeline. Model ids follow ModelSet: hash models first, then the colour parts.
  Status Init(const StereoCalibration& calib, const TableView& table, const PipelineConfig& config,
              ClockFn now_ns = nullptr, const ShapeViewsView* shape_views = nullptr);

  // Recognises the objects in one stereo pair. Images must match the calibration's size.
  // `budget_ms` <= 0 means no time limit. On error the result is empty and the Status names the
  // problem (size mismatch, empty image, ...).
  // `hidden`: n_hidden objects another path found in this frame (the printed cartons; poses in
  // the left-camera frame, models outliving the call). The polyhedral path does not see their
  // silhouettes (PipelineConfig::hide_margin_px), its verifier takes them as occluders, and it
  // reports nothing whose centre lies inside one of them (inside_object.hpp).
  Status Process(ConstGrayView left, ConstGrayView right, float budget_ms, PipelineResult* out,
                 const PosedModel* hidden = nullptr, size_t n_hidden = 0);
  // Frames of any format: the polyhedral path reads their grey (the luma plane in place, RGB
  // converted), the shape path runs on colour frames when a view database was given. The shape
  // path runs first: the colour parts it finds join `hidden` for the polyhedral path, so a part
  // is reported once, by its own path, and its outline spends none of the polyhedral search. Its
  // objects follow the polyhedral path's in `out->objects`. Of `hidden` and the colour parts,
  // the first kMaxHiddenObjects are hidden (the rest: hidden_not_masked).
  Status Process(const FrameView& left, const FrameView& right, float budget_ms,
                 PipelineResult* out, const PosedModel* hidden = nullptr, size_t n_hidden = 0);

  // Views of the last frame's edge maps and features (valid until the next Process()), for
  // overlays and diagnostics.
  ConstEdgeMapView left_edges() const;
  ConstEdgeMapView right_edges() const;
  const Scene& scene() const;
  const TableView& table() const;
  const ModelSet& models() const { return models_; }
  // The colour parts' recogniser; null unless the view database of the last Init() holds models.
  const ShapeRecognizer* shape() const { return shape_.get(); }
  const StereoCalibration& calibration() const;
  const PipelineConfig& config() const { return config_; }
  int threads() const { return pool_.threads(); }
  // The worker pool (started at Init), idle between Process() calls: the firmware runs the
  // texture path on it after the pipeline.
  WorkerPool* pool() { return &pool_; }
  // The plane carried between frames (PipelineConfig::table_carry). Init() starts again from
  // no plane; a caller re-initialising a pipeline whose cameras did not move (another model
  // mask) puts the carried state back.
  const TableCarry& table_carry() const { return carry_; }
  void RestoreTableCarry(const TableCarry& carry) { carry_ = carry; }
  // Lends the one-image recogniser of the rescue stage (PipelineConfig::rescue), or takes it
  // back (null). It must be initialised for the left camera of this calibration with the hash
  // tables' models in their order (the table pose, if any, that of PipelineConfig::table), and
  // stay unused elsewhere while Process() runs: the firmware lends its one-camera fallback's.
  // While lent, it evaluates a scene basis's hypotheses on the pool's threads
  // (MonoRecognizer::SetParallel); taken back, on its caller's alone. Init() takes it back (lend
  // it again after Init).
  Status LendRescue(MonoRecognizer* mono);
  // Diagnosis only (bench tools): sees every hypothesis of the following frames' searches.
  void SetSearchObserver(SearchObserver* observer) { recognizer_.SetObserver(observer); }
  const ImageFeatures& left_features() const { return features_[0]; }
  const ImageFeatures& right_features() const { return features_[1]; }
  // The grey images of the last frame with their measured noise, as the verifier saw them
  // (views of the caller's frame: valid while it is).
  GreyEvidence grey_evidence(int image) const {
    return {frame_images_[image], features_[image].chosen.noise_sigma};
  }
  // The feature workspace of one image (0 left, 1 right), lent between frames to another
  // recogniser on the same thread (the one-camera fallback): its contents change.
  FeatureWorkspace& workspace(int image) { return workspace_[image == 0 ? 0 : 1]; }

 private:
  float MsSince(int64_t start_ns) const;
  void RefineOnEdges(const PosedModel* hidden, size_t n_hidden, PipelineResult* out);
  static void RefineOne(void* self, int index);  // object `index` of refine_out_, on the pool
  // One search of the scene with frame_table_ (objects, stats and verifier counts into out).
  Status Search(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                PipelineResult* out, int64_t* verify_ns);
  // Search() once more, its objects replacing the last search's, the counts of both kept.
  Status SearchAgain(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                     PipelineResult* out, int64_t* verify_ns);
  // The search of a frame with the given table, none, or the plane estimated from the objects
  // of a first search (the second search with it replacing the first's objects).
  Status EstimateAndSearch(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                           PipelineResult* out, int64_t* verify_ns);
  // The table estimated from the objects found, and its use (TableEstimateConfig).
  Status UseEstimatedTable(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                           PipelineResult* out, int64_t* verify_ns);
  // One search with the carried plane as the frame's table, and the check of the plane.
  Status UseCarriedTable(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                         PipelineResult* out, int64_t* verify_ns);
  // The features outside the space over frame_table_ leave the scene (table_ms, counts).
  void KeepOverFrameTable(PipelineResult* out);

  // Sizes the feature workspaces and the grey buffers for the calibration's images.
  Status InitImageBuffers(const StereoCalibration& calib, bool rgb_frames);
  static void ExtractOne(void* self, int image);
  // Steps 1-6 of the polyhedral path on grey images; frame_t0 is the frame's start (the budget
  // covers the whole frame), t0 the path's (its stage times).
  Status RecognisePolyhedra(ConstGrayView left, ConstGrayView right, float budget_ms,
                            int64_t frame_t0, int64_t t0, const PosedModel* hidden, size_t n_hidden,
                            PipelineResult* out);
  // The one-image rescue (PipelineConfig::rescue) after the search: objects added to out.
  Status Rescue(const Budget& budget, PipelineResult* out);
  // One image's part of it (0 left, 1 right; the recogniser set up for that camera).
  Status RescueInImage(int side, const Budget& budget, PipelineResult* out);
  // The rescue's searches: the left image, then the right one when configured.
  Status RescueInBothImages(const Budget& budget, PipelineResult* out);
  // Drops the objects whose centre lies inside a hidden object (after the edge fit moved them).
  void DropInsideHidden(const PosedModel* hidden, size_t n_hidden, PipelineResult* out);
  // The masks of both images from the hidden objects (counts into out).
  void BuildMasks(const PosedModel* hidden, size_t n_hidden, PipelineResult* out);

  bool initialised_ = false;
  StereoCalibration calib_;
  TableView table_;
  PipelineConfig config_;
  ClockFn now_ns_ = nullptr;

  // Per image: detector workspace (buffers sized by Init for the calibration's image size, about
  // 12.7 MiB each at 1280 x 800; holds the edge map) and its features.
  FeatureWorkspace workspace_[2];
  ImageFeatures features_[2];
  // Detector output in stereo's input form.
  StereoPoint2D stereo_points_[2][kMaxStereoCorners];
  StereoLine2D stereo_lines_[2][kMaxStereoLines];
  SloppyStereo stereo_;
  Scene scene_;
  Recognizer recognizer_;  // ~3 MB of vote and candidate tables
  EdgeMapVerifier verifier_;
  TableConstraint frame_table_;  // the table of the current frame: given, estimated or none
  TableCarry carry_;             // the plane carried between frames
  WorkerPool pool_;              // started at Init

  // Per-frame state of the parallel feature extraction (one slot per image).
  ConstGrayView frame_images_[2];
  Status frame_status_[2];
  // Per-frame state of the parallel final edge fit.
  const PosedModel* refine_hidden_ = nullptr;
  size_t refine_n_hidden_ = 0;
  PipelineResult* refine_out_ = nullptr;
  // Silhouettes of the frame's hidden objects, per image (empty: nothing hidden).
  HiddenMask masks_[2];
  // The rescue's recogniser (lent, not owned), the left image's silhouettes of the hidden and
  // accepted objects, and its objects (the accepted ones first).
  MonoRecognizer* rescue_ = nullptr;
  HiddenMask rescue_mask_;
  Vector<RecognizedObject, kMaxObjects> rescue_objects_;
  // The shape path (26 MiB) is allocated by Init only when the model set holds colour parts, so
  // a pipeline without them neither holds nor locks its buffers (docs/memory.md); then the grey
  // images of RGB frames for the polyhedral path.
  ModelSet models_;
  bool shape_enabled_ = false;
  ZeroedPtr<ShapeRecognizer> shape_;
  // The frame's colour parts (appended to the polyhedra's objects at the end) and the objects
  // hidden from the polyhedral path: the caller's, then those colour parts.
  Vector<RecognizedObject, kMaxObjects> shape_objects_;
  PosedModel hidden_[kMaxHiddenObjects];
  // Carved by Init for each camera's image size (one block).
  InitBlock grey_block_;
  uint8_t* grey_[2] = {nullptr, nullptr};
  int grey_width_[2] = {0, 0}, grey_height_[2] = {0, 0};
};

}  // namespace sh
