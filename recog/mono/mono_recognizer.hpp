// Recognition from one image by 2-D geometric hashing over aspect models (thesis ch. 6), with a
// 6-D pose per object.
//
// Per frame: the image's corners and lines are taken to ideal (undistorted) image coordinates;
// scene bases (corner pairs for similarity tables, triples for affine ones) are ordered so that
// corners joined by an image line come first; for each scene basis the aspect voter proposes
// model bases, each hypothesis becomes a 6-D pose (PoseFromHypothesis), which with a table is
// laid onto a stable face of the model (depth and tilt fixed) and then refined by the
// reprojection error of matched corners and lines; the refined pose is verified against the
// image's edge pixels with true hidden lines and the objects found so far as occluders, and the
// verified hypothesis that explains most edge samples is accepted. Its corners and lines leave
// the scene and the search goes on with the next untried scene basis.
//
// Statically allocated; Recognize() does not touch the heap.
#pragma once

#include <cstdint>

#include "recog/base/ahead_batch.hpp"
#include "recog/base/parallel_for.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/image/feature_mask.hpp"
#include "recog/image/features.hpp"
#include "recog/mono/aspect_voter.hpp"
#include "recog/mono/mono_pose.hpp"
#include "recog/mono/resting_pose.hpp"
#include "recog/verify/verify.hpp"
#include "recog/verify/view_camera.hpp"
#include "tables/aspect_view.hpp"

namespace sh {

// Capacities (compile-time; docs/architecture.md).
inline constexpr size_t kMaxMonoSceneBases = 16384;  // candidate scene bases per frame
inline constexpr int kMaxMonoHypotheses = 8;         // model bases tried per scene basis
// With a ParallelFor (MonoRecognizer::SetParallel): the most threads that evaluate a scene
// basis's hypotheses, each in its slot of scratch.
inline constexpr int kMonoEvaluationSlots = 2;
// With lent vote counters as well (MonoRecognizer::LendVoteCounters): the scene bases voted at
// once, in turn on the two voters, ahead of their turn in the search.
inline constexpr uint32_t kMonoVoteAheadBases = 4;

// Edge-pixel verification in the one image: samples confirmed within 3 px (thesis 4 px) and at
// least half of them (thesis 40 %), as there is no second image to reject a wrong model.
inline VerifyConfig MonoVerifyConfig() {
  VerifyConfig v;
  v.max_distance_px = 3.0f;
  v.min_fraction = 0.5f;
  return v;
}

struct MonoConfig {
  VoterConfig voter;
  float vote_threshold = 0.3f;  // normalised vote (0..2) for a hypothesis
  int hypotheses_per_basis = 8;
  // Scene basis sides in ideal pixels (thesis 6.4.3: 40 .. 200 px).
  float min_basis_px = 30.0f;
  float max_basis_px = 250.0f;
  // Try only corner pairs (triples) joined by image lines: objects show most of their edges, and
  // the other pairs mostly join corners of different things.
  bool connected_bases_only = true;
  // Corners whose surrounding gradients keep to one direction are points on an edge, not
  // corners: sensor noise makes the corner response peak along every high-contrast edge, and on
  // a factory floor (long boxes, cylinders, shadows) such points outnumber the corners several
  // times and use up the bases. The measure is the vertex refinement's (CornerConfig::
  // refine_to_vertex): the smaller eigenvalue of the gradients' structure tensor over its trace,
  // Corner2D::isotropy, which is (1 - cos a) / 2 for two edges whose normals differ by a:
  // 0.008 is a = 10 deg, a corner of 170 deg. Such points form no scene basis; they still take
  // part in matching.
  float min_corner_isotropy = 0.008f;
  // A corner belongs to a line when it lies this close to it and within its support (with the
  // margin) along it.
  float corner_line_distance_px = 3.0f;
  float corner_line_margin_px = 8.0f;
  // Add a corner where two lines at a proper angle both end (within the gap) at their
  // intersection and no detected corner lies within 4 px.
  bool junction_corners = true;
  float junction_gap_px = 8.0f;
  // Stop after this many scene bases in a row gave no object.
  uint32_t max_fruitless_bases = 30;
  MatchConfig match;
  FitConfig fit;
  // Gates of the successive match-and-fit rounds, pixels.
  float round_gates_px[3] = {12.0f, 6.0f, 3.5f};
  int min_matched_features = 4;  // after the last round
  // Share of the model's visible corners and edge pieces that must find an image feature: a
  // wrong model fitted to part of an object predicts features the image does not have.
  float min_match_fraction = 0.6f;
  // ... and a start pose must match this share within the first round's gate.
  float early_match_fraction = 0.3f;
  // With a table: a hypothesis starts on the stable faces whose resting view is within this of
  // its aspect's view (at the camera's elevation where the basis lies), and only when the two
  // basis corners placed on the table lie this fraction off the model's distance at most.
  float max_tilt_deg = 35.0f;
  float max_depth_error = 0.2f;
  // Table mode: model bases whose size, at the depths the table allows along the scene basis's
  // viewing ray, differs from the scene basis's by more than this fraction get no votes.
  float max_scale_error = 0.35f;
  // Aspects are used only when their view is within this of a view of a resting object from
  // the camera (table mode).
  float aspect_view_margin_deg = 25.0f;
  VerifyConfig verify = MonoVerifyConfig();
  float min_object_separation_mm = 15.0f;  // two objects cannot have centres this close
  // Untried scene bases with a corner among a verified candidate's matched corners, tried
  // before it is accepted; a candidate they find that shares at least this share of the
  // smaller one's matched image features is the same object, and the one with more evidence
  // wins. Five rather than two: the right model's first bases among the object's corners are
  // often not the next two (on a factory floor, under sensor noise, a hexagon prism's corners
  // pair with a trapezium's hypotheses first); over twenty polyhedral sets with one camera five
  // found 7 objects more with 7 false alarms fewer (six and eight, on eleven of the sets, no
  // more than five), for about a fifth more frame time.
  int competing_bases = 5;
  float competing_overlap = 0.5f;
  // Solids do not interpenetrate: a candidate whose corner centroid lies inside an object found
  // before, or that holds its centroid, is rejected, unless (displace_weaker) it interpenetrates
  // only that one and has more evidence: then it takes its place.
  bool exclude_interpenetrating = true;
  bool displace_weaker = true;
  // Evidence = confirmed edge samples - this x unconfirmed ones.
  float missing_edge_penalty = 0.5f;
  float hidden_line_step_px = 2.0f;  // sampling of the hidden lines for the matching
};

struct MonoStats {
  uint32_t scene_bases_available = 0;
  uint32_t scene_bases_tried = 0;
  uint32_t hypotheses = 0;
  uint32_t rejected_tilt = 0;   // no stable face shows the aspect's view (table mode)
  uint32_t rejected_depth = 0;  // basis corners on the table too near or far apart (table mode)
  uint32_t rejected_matches = 0;
  uint32_t rejected_overlap = 0;  // too close to an object already found
  uint32_t verifications = 0;
  uint32_t rejected_verify = 0;
  uint32_t accepted = 0;
  uint32_t aspects_enabled = 0;
  // A fingerprint of the votes the search took, in order (each hypothesis's scene basis, model
  // basis and vote; FNV-1a): equal searches give equal digests, on any number of threads.
  uint32_t votes_digest = 2166136261u;
  bool budget_exhausted = false;
  bool objects_full = false;
};

// Why an object was not found, judged at its true pose (diagnostics for benchmarks).
struct MonoDiagnosis {
  int corners_visible = 0;    // 2-D corners the model shows at the true pose
  int corners_detected = 0;   // of those, with a detected corner within 3 px
  int pieces_visible = 0;     // visible edge pieces long enough to match
  int pieces_detected = 0;    // of those, with a detected line
  float verify_fraction = 0;  // edge samples confirmed at the true pose
  int verify_samples = 0;
  int object_bases = 0;      // scene bases (in the candidate list) on two of its corners
  int bases_with_model = 0;  // of those, bases whose hypotheses include the right model
  int bases_found = 0;       // bases whose evaluation ends near the true pose
  int best_rank = -1;        // rank of the first such basis in the candidate order
  MonoStats stats;           // what happened to the right model's hypotheses
};

// Its scratch members are written before they are read: initialising them would make every page
// of the workspace resident (docs/memory.md).
// NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init)
class MonoRecognizer {
 public:
  // `camera`: the image's intrinsics and its pose relative to the left camera (poses are
  // reported in the left camera's frame, as by the stereo pipeline). `left_T_table`: the table's
  // pose in the left camera frame, or null for free 6-D poses.
  Status Init(const ViewCamera& camera, const AspectTableView& table,
              const RigidTransform* left_T_table, const MonoConfig& config);
  const MonoConfig& config() const { return config_; }
  bool has_table() const { return has_table_; }
  // Another table (left-camera frame; null: none, free 6-D poses) for the following frames,
  // without allocating: the stereo pipeline's rescue lends the plane it estimated to a
  // recogniser set up without one. A table the camera is not above is refused, nothing changed.
  Status SetTable(const RigidTransform* left_T_table);
  // Another camera of the rig (intrinsics and pose relative to the left camera) for the
  // following frames, the table kept where it is in the left camera's frame, without
  // allocating: the stereo pipeline's rescue searches the right image with the recogniser set
  // up for the left one, and sets it back. A camera that is not above the table, or invalid
  // intrinsics, are refused with nothing changed.
  Status SetCamera(const ViewCamera& camera);
  const ViewCamera& camera() const { return camera_; }

  // A scene basis's hypotheses evaluated over `threads` threads (kMonoEvaluationSlots at most
  // are used) of `parallel` (the pipeline's worker pool), each thread in its slot of scratch,
  // then the best taken as the serial loop takes it (most evidence, the first on a tie), so the
  // results equal those on the calling thread alone (threads 1, or a ParallelFor without a
  // pool). The voting stays on the caller unless vote counters are lent (LendVoteCounters). No
  // allocation; a later Init() keeps the setting. Errors: Init() has not succeeded, threads
  // below 1.
  Status SetParallel(const ParallelFor& parallel, int threads);
  int evaluation_threads() const { return slots_used_; }

  // Memory another stage lends while it is idle (the stereo pipeline's rescue: the stereo
  // recogniser's second vote scratch), `size` bytes at `bytes`, for a second voter's counters
  // (AspectVoter::CounterBytes of the table): with two evaluation threads the search then votes
  // the next scene bases it will try, kMonoVoteAheadBases at once over both voters, and takes
  // each basis's votes in its turn (votes taken before the scene changed are thrown away), so
  // the results equal those on the calling thread alone. The block may hold anything and is
  // overwritten; it must stay lent until LendVoteCounters(nullptr, 0) or Init(). A block too
  // small is refused (kResourceExhausted) and the votes stay on the caller, as with none.
  // Errors: Init() has not succeeded.
  Status LendVoteCounters(uint8_t* bytes, size_t size);
  // Whether the search votes over two voters (lent counters and two evaluation threads).
  bool votes_in_parallel() const { return lent_voter_ready_ && slots_used_ > 1; }

  // Recognises objects in one image's features (corners, lines and the edge map of that
  // image). `objects` is cleared first; poses are left-camera frame; verify_score[0] is the
  // confirmed fraction in this image, verify_score[1] the fraction of the model's visible
  // corners and edges matched.
  Status Recognize(const ImageFeatures& features, const Budget& budget,
                   Vector<RecognizedObject>& objects, MonoStats* stats = nullptr);

  // Recognises what known objects do not explain (the stereo pipeline's rescue stage): the
  // first n_known entries of `objects` (left-camera frame, models of this table) are kept, hide
  // what lies behind them and are never displaced; a candidate that interpenetrates one is
  // rejected. Image corners and lines that `ignore` hides (the known objects' silhouettes) take
  // no part. Objects found are appended after the known ones.
  Status RecognizeRest(const ImageFeatures& features, const FeatureMask& ignore,
                       const Budget& budget, Vector<RecognizedObject>& objects, size_t n_known,
                       MonoStats* stats = nullptr);
  const AspectTableView& table() const { return table_; }

  // The last frame's image corners (distorted pixels): the detected ones, then those added at
  // line junctions (for overlays and diagnostics).
  int corner_count() const { return n_corners_; }
  int junction_corner_count() const { return junction_corners_; }
  Eigen::Vector2f corner(int i) const { return pose_corners_[i].px; }

  // Diagnostics: how recognition fares for one object of known model and pose (left-camera
  // frame) in these features, each scene basis on it evaluated alone (nothing else found).
  Status Diagnose(const ImageFeatures& features, int model, const RigidTransform& left_T_model,
                  MonoDiagnosis* out);

 private:
  struct Candidate {
    uint16_t model = 0;
    RigidTransform cam_T_model;
    RestingPose rest;
    PoseMatches matches;
    float vote = 0;
    float fit_rms_px = 0;
    float score = 0;
    float evidence = 0;
    float match_fraction = 0;
    int displaces = -1;  // the object found before whose place it takes, or -1
  };
  void UseCamera(const ViewCamera& camera);  // the camera and what follows from it
  Status PrepareScene(const ImageFeatures& features, const FeatureMask* ignore);
  // The search over the prepared scene, after the first n_known objects.
  void Search(const Budget& budget, Vector<RecognizedObject>& objects, size_t n_known,
              MonoStats* stats);
  struct SceneBasis2d;
  Frame2d BasisFrame(const SceneBasis2d& sb) const;
  bool BasisActive(const SceneBasis2d& sb) const;
  // True if candidate k lies in the image circle of an object found after it was tried.
  bool NearLaterObject(uint32_t k, size_t n_objects) const;
  // Votes for candidate k and evaluates its hypotheses; the best verified one goes to *best.
  bool TryBasis(uint32_t k, const Vector<RecognizedObject>& objects, MonoStats* stats,
                Candidate* best);
  // Whether the search's current pass tries candidate k when it comes to it (the scene as now).
  bool PassTries(uint32_t k, size_t n_objects) const;
  // The votes of candidate k (hypotheses into `out`, their number returned) on the scene as it
  // is now: voted ahead, or voted now (with the next bases of the pass when votes_in_parallel,
  // `most` in all at the most).
  int VoteInTurn(uint32_t k, size_t n_objects, uint32_t most, AspectHypothesis* out);
  // Candidate k's votes with `voter`.
  int VoteBasis(AspectVoter& voter, uint32_t k, AspectHypothesis* out) const;
  // Scratch of one evaluation slot (slot 0: the caller's); written before it is read, as the
  // class's.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init)
  struct SlotScratch {
    Candidate candidate;
    VisibleEdgeSet visible;
    FitScratch fit;
    Candidate best;       // the slot's best (slot 0 keeps it in the caller's candidate)
    int best_index = -1;  // its hypothesis, -1: none verified
    MonoStats stats;      // the slot's evaluations' counts
  };
  // The hypotheses of the scene basis being evaluated (TryBasis), read by the slots.
  struct EvaluationJob {
    const AspectHypothesis* hyps = nullptr;
    int n = 0;
    int slots = 1;  // hypothesis i goes to slot i % slots
    const Frame2d* frame = nullptr;
    const Vector<RecognizedObject>* objects = nullptr;
    Candidate* best = nullptr;
  };
  static void EvaluateSlot(void* self, int slot);
  // Image features (matched corners and lines) both candidates claim.
  static int SharedFeatures(const Candidate& a, const Candidate& b);
  // Replaces best_ (found from candidate k) by a competitor for the same image features that
  // has more evidence.
  void ChooseAmongCompetitors(uint32_t k, const Vector<RecognizedObject>& objects,
                              MonoStats* stats);
  void AddJunctionCorners();
  // Whether scene corner i may be a basis corner: a junction corner, or an image corner not on
  // an edge (MonoConfig::min_corner_isotropy).
  bool CornerMayBase(int i) const;
  void GenerateBases();
  bool RestingStart(const AspectBasis& basis, const AspectRecord& aspect, const Frame2d& frame,
                    const RigidTransform& hypothesis, MonoStats* stats, RestingPose* out) const;
  bool Evaluate(const AspectHypothesis& h, const Frame2d& scene_frame,
                const Vector<RecognizedObject>& accepted, SlotScratch& scratch, MonoStats* stats,
                Candidate* out);
  void Accept(const Candidate& c, Vector<RecognizedObject>& objects);
  // An object's image circle (ideal pixels: centre and reach) in this camera's frame.
  Eigen::Vector3f ImageCircle(const Model& model, const RigidTransform& cam_T_model) const;
  // Takes object `index` out of the result: its image features are free again.
  void Remove(size_t index, Vector<RecognizedObject>& objects);
  void ComputeBasisKeys();
  void KeyRange(const Frame2d& frame, VoteRequest* request) const;

  bool initialised_ = false;
  ViewCamera camera_;  // intrinsics, cam_T_left
  RigidTransform left_T_cam_;
  float ideal_focal_px_ = 1;
  AspectTableView table_;
  MonoConfig config_;
  bool has_table_ = false;
  TablePlane plane_;  // in this camera's frame
  StableFaces stable_[kMaxAspectModels];
  AspectVoter voter_;
  // The second voter, its counters in lent memory (LendVoteCounters).
  AspectVoter lent_voter_;
  bool lent_voter_ready_ = false;
  // Per model basis: its apparent size, millimetres at the virtual camera's distance (the image
  // size is ideal_focal * key / depth); NaN for bases of aspects a resting object cannot show.
  float basis_key_[kMaxAspectBases];
  float max_object_height_mm_ = 0;
  float max_model_radius_mm_ = 0;
  uint32_t aspects_enabled_ = 0;

  // Per frame.
  const ImageFeatures* features_ = nullptr;
  size_t n_known_ = 0;               // leading objects given by the caller (RecognizeRest)
  int n_corners_ = 0, n_lines_ = 0;  // corners: detected ones, then junction corners
  int junction_corners_ = 0;
  ScenePoint2d ideal_points_[kMaxCorners2d];
  SceneLine2d ideal_lines_[kMaxLines2d];
  PoseCorner pose_corners_[kMaxCorners2d];
  PoseLine pose_lines_[kMaxLines2d];
  uint8_t corner_active_[kMaxCorners2d];
  uint8_t line_active_[kMaxLines2d];
  struct SceneBasis2d {
    uint16_t corners[3] = {0, 0, 0};
    float score = 0;
  };
  SceneBasis2d candidates_[kMaxMonoSceneBases];
  uint8_t tried_[kMaxMonoSceneBases];           // 0 untried, 1 failed, 2 done
  uint8_t tried_at_[kMaxMonoSceneBases];        // objects found when it was tried
  Eigen::Vector3f object_circle_[kMaxObjects];  // image centre and reach of each object found
  // Scratch of the search (large: kept off the stack): slot 0 the caller's, the others for the
  // hypotheses evaluated on other threads (SetParallel).
  Candidate best_, other_;
  SlotScratch slots_[kMonoEvaluationSlots];
  ParallelFor parallel_;
  int slots_used_ = 1;
  EvaluationJob job_;
  // Scene bases voted ahead of their turn (VoteInTurn): valid until the scene's active
  // features change (Accept, Remove) or the search starts again.
  struct BasisVotes {
    int n = 0;
    AspectHypothesis hyps[kMaxMonoHypotheses];
  };
  using AheadVotes = AheadBatch<BasisVotes, kMonoVoteAheadBases>;
  AheadVotes ahead_;
  int pass_ = 0;                  // the search's pass
  uint32_t max_scene_bases_ = 0;  // the search's budget
  uint32_t n_candidates_ = 0;
  // Corners near each line (ideal for connected pairs), at most kMaxLineCorners per line.
  static constexpr int kMaxLineCorners = 16;
  uint16_t line_corners_[kMaxLines2d][kMaxLineCorners];
  uint8_t n_line_corners_[kMaxLines2d];
  // Image features each accepted object took (scene corner and line indices).
  int16_t claimed_points_[kMaxObjects][kMaxMatchedCorners];
  int16_t claimed_lines_[kMaxObjects][kMaxMatchedPieces];
  uint8_t n_claimed_points_[kMaxObjects];
  uint8_t n_claimed_lines_[kMaxObjects];
  // Accepted objects as occluders (this camera's frame).
  PosedModel occluders_[kMaxOccluders];
  size_t n_occluders_ = 0;
};

}  // namespace sh
