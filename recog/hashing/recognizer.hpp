// Recognition by 3-D geometric hashing (thesis ch. 2, 4, 5), statically allocated (the vote
// arrays of extra voting threads are allocated once, at start-up: SetParallel).
//
// For a scene basis, every other scene feature is expressed in the basis frame and looked up in
// the hash arrays; each model entry near it receives a Gaussian vote (at most one, the best, per
// scene basis). Model bases whose normalised vote (point part / point entries + line part / line
// entries, in [0, 2]) reaches the threshold become hypotheses; each is refined with all
// supporting features and handed to a verifier. An accepted object's features, and every 3-D
// feature sharing a 2-D feature with them, leave the scene; the search continues with the next
// untried scene basis until the budget, the scene bases or the features run out.
//
// Beyond the thesis: scene bases tried for one object are never tried again for the next, the
// order of scene bases is a policy, and the search honours a budget (scene bases or a deadline)
// and returns what it has verified so far when the budget runs out.
//
// The parts: scene_topology (which lines end at which points), basis_candidates (the ordering
// policy), and here the voting and the search with refinement and verification.
#pragma once

#include <cstdint>

#include "recog/base/ahead_batch.hpp"
#include "recog/base/parallel_for.hpp"
#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/hashing/basis.hpp"
#include "recog/hashing/basis_candidates.hpp"
#include "recog/hashing/line_direction_index.hpp"
#include "recog/hashing/line_look_up.hpp"
#include "recog/hashing/pose_refine.hpp"
#include "recog/hashing/scene_grid.hpp"
#include "recog/hashing/scene_state.hpp"
#include "recog/hashing/scene_topology.hpp"
#include "recog/hashing/vote_lut.hpp"
#include "recog/scene/scene.hpp"
#include "tables/table_view.hpp"

namespace sh {

// Capacities (compile-time; see docs/architecture.md).
inline constexpr size_t kMaxObjects = 32;            // recognised objects per scene
inline constexpr size_t kMaxHypothesesPerBasis = 8;  // model bases tried per scene basis
// With two threads or more: scene bases voted ahead at once, spread over the threads
// (Recognizer::SetParallel), and the most threads that vote.
inline constexpr uint32_t kVoteAheadBases = 16;
inline constexpr int kMaxVoteThreads = 8;
// Competition at acceptance (RecognizerConfig::compete_bases): the most scene bases voted at an
// accepted object's place, and how far down the candidate list they are looked for.
inline constexpr int kMaxCompeteBases = 8;
inline constexpr uint32_t kCompeteScanBases = 64;
// Weakly confirmed objects held back until the search ends (RecognizerConfig::defer_below_score);
// when full, a stronger one takes the weakest one's slot.
inline constexpr size_t kMaxDeferredObjects = 16;

struct RecognizerConfig {
  float sigma_point_mm = 2.0f;             // vote width for points
  float sigma_line_mm = 2.0f;              // vote width for lines
  float vote_threshold = 0.2f;             // normalised vote needed for a hypothesis (thesis: 0.2)
  float line_neighbourhood_factor = 3.5f;  // appendix B: support vectors differ up to 3.5 x
  int hypotheses_per_basis = 3;            // best model bases refined per scene basis
  BasisOrder order = BasisOrder::kQuality;
  uint32_t random_seed = 1;
  uint32_t model_mask = 0xffffffffu;  // bit m enables model m (the active model set)
  int min_active_features = 6;        // stop when fewer scene features remain
  // Stop after this many scene bases in a row produced no object: in clutter, the bases that
  // find objects come early in quality order and the rest of the list only costs time.
  uint32_t max_fruitless_bases = 15;
  float min_object_separation_mm = 15.0f;  // two objects cannot share a centre this close
  float connect_tolerance_mm = 2.5f;       // a line this close to a point or line meets it
  float junction_reach_mm = 12.0f;         // an edge's detected end lies this close to its corner
  float support_gate_sigmas = 1.0f;        // gate for the matched counts handed to the verifier
  // Quality order spread over the scene (BasisCandidates::Policy): score lost per better basis
  // in the same cell, and the cell's size.
  float basis_cell_rank_penalty = 0.0f;
  float basis_cell_size_mm = 50.0f;
  // Look line entries up by direction class (line_direction_index.hpp): the same votes with
  // fewer entries visited. Off: every entry of the neighbourhood, for comparison.
  bool line_direction_index = true;
  // Competition at acceptance: before an object leaves the scene, `compete_bases` untried active
  // scene bases at its place are voted on the scene it is accepted from: first those made only of
  // the features it matched (from the whole rest of the list), then those whose origin lies
  // within the object's model radius of its centre (among the next kCompeteScanBases). A
  // hypothesis of another model there, refined to within min_object_separation_mm of the object's
  // centre and matching more scene features than it (corners and edges within the verifier's
  // gate), replaces the object when its verification explains clearly more
  // (ChallengerClearlyBetter). A model fitting a subset of a larger
  // object's corners and edges (a pentagon prism on a hexagon prism) would otherwise be accepted
  // first and take the features that the larger model needed. 0: off (at most
  // kMaxCompeteBases).
  int compete_bases = 0;
  float compete_evidence_margin = 0.1f;
  float compete_score_margin = 0.05f;
  // A larger model seen in part has no more 3-D features there than the smaller model that
  // fitted them, and its model bases get fewer votes from them (normalised by its larger feature
  // count). Its hypotheses at the object's place may therefore come from model bases voted at
  // compete_vote_factor times vote_threshold (in (0, 1]; below 1 the competition's bases are voted
  // afresh, not taken from the bases voted ahead), and need only compete_extra_matches more
  // matched scene features than the object (corners and edges within the verifier's gate); the
  // verification decides (ChallengerClearlyBetter).
  float compete_vote_factor = 1.0f;
  int compete_extra_matches = 1;
  // Strong confirmations first: a verified object whose lower verification score is below this
  // is not accepted during the search but held back (one per place, the one explaining most), and
  // its features stay in the scene. A wrong pose or a part-fitting model confirmed weakly would
  // otherwise take the features that the true object's later scene bases need. When the search
  // ends, the held-back ones are verified again, strongest first, with the accepted objects as
  // occluders, and accepted where no accepted object stands (closer than
  // min_object_separation_mm, or solids that interpenetrate). 0: off, every verified object is
  // accepted at once.
  float defer_below_score = 0.0f;
  RefineConfig refine;
};

struct Hypothesis {
  uint16_t model = 0;
  uint32_t model_basis = 0;
  SceneBasis scene_basis;
  float vote = 0.0f;  // normalised, [0, 2]
  RigidTransform cam_T_model;
};

struct RecognizedObject {
  uint16_t model = 0;
  uint16_t instance = 0;  // counts objects of the same model in this scene
  RigidTransform cam_T_model;
  float vote = 0.0f;
  float fit_rms_mm = 0.0f;
  uint16_t matched_points = 0;
  uint16_t matched_lines = 0;
  float verify_score[2] = {0.0f, 0.0f};  // verifier's scores (e.g. left, right image)
  // How much of the data the hypothesis explains, in the verifier's units (confirmed edge
  // samples, matched features): ranks verified hypotheses of different models against each
  // other, where fractions favour a model that fits inside another (a wedge on a cube).
  float verify_evidence = 0.0f;
  // The pose before the pipeline's final fit to the image edges (equal to cam_T_model when that
  // fit is off or did not improve it), for reporting both.
  RigidTransform cam_T_model_features;
  bool edge_refined = false;
};

// The competition at acceptance's test (RecognizerConfig::compete_bases): whether a verified
// challenger of another model at an object's place explains the images clearly better than the
// object. Both image scores together must be higher by twice compete_score_margin, and
//  - its evidence (confirmed edge samples) at least (1 + compete_evidence_margin) times the
//    object's, neither score lower by more than compete_score_margin: a smaller model can fit
//    one view of a larger object as well as the larger model does (its edges coincide with the
//    larger one's there), but not both; or
//  - its evidence at least (1 - compete_evidence_margin) times the object's and neither score
//    lower: a model fitting part of an object, posed a little off it, can confirm as many samples
//    along the object's strong edges as the whole object does where its far edges are weak
//    (sensor noise), but not the object's share of them in both images.
bool ChallengerClearlyBetter(const RecognizedObject& challenger, const RecognizedObject& object,
                             const RecognizerConfig& config);

// Decides whether a refined hypothesis is a real object. The stereo pipeline verifies against
// edge pixels; recognition of 3-D scenes alone uses SceneSupportVerifier.
class HypothesisVerifier {
 public:
  virtual ~HypothesisVerifier() = default;
  // `accepted` holds the objects accepted so far in this scene (for occlusion reasoning).
  virtual bool Verify(const Model& model, const Vector<RecognizedObject>& accepted,
                      RecognizedObject& candidate) = 0;
  // Whether Verify may run for several candidates at once (the same `accepted`) on different
  // threads: its verdict and scores depend on its arguments alone, and what it counts does not
  // depend on the order of the calls. The search then verifies the hypotheses of a scene basis
  // in parallel (Recognizer::SetParallel).
  virtual bool ConcurrentVerify() const { return false; }
  // Whether the candidate's solid would pass through one of `accepted` (two objects cannot share
  // space). Without the models' solids (the default): never.
  virtual bool Interpenetrates(const Model& model, const RecognizedObject& candidate,
                               const Vector<RecognizedObject>& accepted) const {
    (void)model, (void)candidate, (void)accepted;
    return false;
  }
};

// Accepts when enough of the model's corners and edges found scene features after refinement
// (mean of the corner and edge fractions at least min_fraction, and at least three of each).
// Scores: {corner fraction, edge fraction}.
class SceneSupportVerifier : public HypothesisVerifier {
 public:
  // min_features: matched corners plus edges, so that small models (the wedge has 15
  // features) are not confirmed by a handful of clutter features.
  explicit SceneSupportVerifier(float min_fraction = 0.5f, int min_features = 8)
      : min_fraction_(min_fraction), min_features_(min_features) {}
  bool Verify(const Model& model, const Vector<RecognizedObject>& accepted,
              RecognizedObject& candidate) override;
  bool ConcurrentVerify() const override { return true; }

 private:
  float min_fraction_;
  int min_features_;
};

// Sees the steps of the search, for diagnosis (the bench tools explain misses with it);
// recognition never needs one.
class SearchObserver {
 public:
  enum class Outcome : uint8_t { kTooClose, kRejected, kVerified };
  virtual ~SearchObserver() = default;
  // A hypothesis of the scene basis tried as number `basis_number` (from 0), refined into
  // `candidate`, and what became of it.
  virtual void OnHypothesis(uint32_t basis_number, const Hypothesis& h,
                            const RecognizedObject& candidate, Outcome outcome) = 0;
  // The object accepted from that scene basis.
  virtual void OnAccepted(uint32_t basis_number, const RecognizedObject& object) = 0;
};

struct Budget {
  uint32_t max_scene_bases = 0xffffffffu;
  // Stop once this many objects are accepted (0: no limit); not counted as budget_exhausted.
  uint32_t max_objects = 0;
  int64_t deadline_ns = 0;        // 0: no deadline
  int64_t (*now_ns)() = nullptr;  // clock for the deadline (monotonic)
};

struct RecognitionStats {
  uint32_t scene_bases_tried = 0;
  uint32_t scene_bases_available = 0;  // candidates generated, both passes (each capped)
  uint32_t hypotheses = 0;
  uint32_t verifications = 0;
  uint32_t accepted = 0;
  uint32_t deferred = 0;           // weakly confirmed places held back (defer_below_score)
  uint32_t deferred_accepted = 0;  // of them accepted when the search ended (in `accepted`)
  bool budget_exhausted = false;
  bool objects_full = false;
};

class Recognizer {
 public:
  Status Init(const TableView& table, const RecognizerConfig& config);
  // Voting spread over `threads` threads (`parallel` concurrent: the pipeline's worker pool;
  // at most kMaxVoteThreads are used) or on the caller alone (threads 1, or a ParallelFor
  // without a pool). With two or more, Recognize votes the next kVoteAheadBases active scene
  // bases at once, spread over the threads, then takes them in order; an accepted object
  // changes the scene, and the bases voted ahead of it are voted again when their turn comes.
  // Each vote is thus made on the scene the sequential search would see, and the results are
  // the same for any thread count. Allocates the vote arrays of the threads beyond the caller
  // (about 0.9 MB each) when first asked for them: at start-up, never per frame. Errors: memory.
  Status SetParallel(const ParallelFor& parallel, int threads);
  const RecognizerConfig& config() const { return config_; }

  // The first `bytes` bytes of the second voting thread's arrays as raw memory, lent while this
  // recogniser is idle (the stereo pipeline's rescue votes in them): {null, 0} when there are
  // none (fewer than two vote threads allocated) or they are smaller. The borrower may write
  // anything there until the next Recognize(), which clears those bytes first (the vote arrays
  // are all zero between rounds), as Init() does.
  struct LentMemory {
    uint8_t* bytes = nullptr;
    size_t size = 0;
  };
  LentMemory LendVoteScratch(size_t bytes);
  // Diagnosis only: `observer` (may be null) sees every hypothesis of later searches.
  void SetObserver(SearchObserver* observer) { observer_ = observer; }
  const TableView& table() const { return table_; }

  // Recognises objects in `scene`; `objects` is cleared first. No heap allocation.
  Status Recognize(const Scene& scene, HypothesisVerifier& verifier, const Budget& budget,
                   Vector<RecognizedObject>& objects, RecognitionStats* stats = nullptr);

  // One voting round for one scene basis against the current scene (after PrepareScene):
  // fills `out` with the best hypotheses above the threshold. For tests and benchmarks.
  void PrepareScene(const Scene& scene);
  // If best_per_model is given (kMaxTableModels floats), it receives every model's best
  // normalised vote, whether above the threshold or not.
  int VoteForBasis(const SceneBasis& basis, Vector<Hypothesis>& out,
                   float* best_per_model = nullptr);
  // Scene bases in the configured order (generated by PrepareScene).
  uint32_t CandidateCount() const { return candidates_.count(); }
  const SceneBasis& Candidate(uint32_t i) const { return candidates_[i]; }

 private:
  bool SceneBasisFrame(const SceneBasis& b, RigidTransform* basis_T_cam,
                       Eigen::Vector3f* shape_point) const;
  // The arrays of one voting round (one scene basis), one set per voting thread.
  struct VoteScratch {
    uint16_t point_vote[kMaxTablePointEntries];
    uint16_t line_vote[kMaxTableLineEntries];
    uint32_t touched_points[kMaxTablePointEntries];
    uint32_t touched_lines[kMaxTableLineEntries];
    uint32_t n_touched_points = 0, n_touched_lines = 0;
    uint32_t basis_point_sum[kMaxTableBases];
    uint32_t basis_line_sum[kMaxTableBases];
    uint16_t touched_bases[kMaxTableBases];
    uint8_t basis_touched[kMaxTableBases];
    uint32_t n_touched_bases = 0;
  };
  // The hypotheses of a scene basis voted ahead of its turn.
  using AheadVotes = AheadBatch<Vector<Hypothesis, kMaxHypothesesPerBasis>, kVoteAheadBases>;

  // `threshold` < 0: config_.vote_threshold.
  int Vote(const SceneBasis& b, VoteScratch& scratch, Vector<Hypothesis>& out,
           float* best_per_model, float threshold = -1.0f) const;
  void VotePoint(const Eigen::Vector3f& q, VoteScratch& scratch) const;
  void VoteLine(const Eigen::Vector3f& s, const Eigen::Vector3f& v, VoteScratch& scratch) const;
  void VoteLineEntry(const LineDirectionIndex::Entry& l, const LineLookUp& q,
                     VoteScratch& scratch) const;
  void VoteKeptLineEntry(const LineDirectionIndex::Entry& l, const LineLookUp& q,
                         VoteScratch& scratch) const;
  // The hypotheses of candidate `index` (basis `b`) of the current pass: from the bases voted
  // ahead when it is among them, else voted now (with two threads or more: together with the
  // next active bases, `most` bases in all at the most, this one included).
  int VoteInTurn(uint32_t index, const SceneBasis& b, uint32_t most, Vector<Hypothesis>& out);
  void RemoveObjectFeatures(const Model& model, const Correspondences& c);
  int ActiveFeatureCount() const;
  // Whether every feature of b has its flag set (per scene point and per scene line).
  bool BasisFlagged(const SceneBasis& b, const uint8_t* point_flag, const uint8_t* line_flag) const;
  bool BasisActive(const SceneBasis& b) const;
  bool TooCloseToAccepted(const RigidTransform& cam_T_model,
                          const Vector<RecognizedObject>& objects) const;
  // RecognizerConfig::defer_below_score: whether `object` waits, holding it back if so.
  bool Defer(const RecognizedObject& object, RecognitionStats& stats);
  // The held-back objects, strongest first, verified again and accepted where nothing stands
  // (sorts deferred_; the caller clears it).
  void AcceptDeferred(HypothesisVerifier& verifier, const Budget& budget,
                      Vector<RecognizedObject>& objects, RecognitionStats& stats);
  // A refined and verified candidate of hypothesis `h` (the search's step for each hypothesis);
  // false when it is too close to an accepted object, matches fewer than `min_matched` scene
  // features within the verifier's gate (not verified then) or is rejected. Reports verified,
  // rejected and too-close hypotheses to the observer.
  bool RefineAndVerify(const Hypothesis& h, uint32_t basis_number, RefineInput& refine_in,
                       const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                       RecognitionStats& stats, RecognizedObject* candidate,
                       Correspondences* matches, int min_matched = 0);
  // A hypothesis refined, its support within the verifier's gate counted and, with at least
  // `min_matched`, verified: what RefineAndVerify computes without reporting it.
  struct Evaluated {
    RecognizedObject candidate;
    Correspondences matches;
    bool too_close = false;
    bool enough = false;  // matched at least min_matched within the gate: verified
    bool verified = false;
  };
  void Evaluate(const Hypothesis& h, const RefineInput& refine_in,
                const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                int min_matched, Evaluated* out) const;
  // RefineAndVerify's report of an evaluated hypothesis (observer, counts, results).
  bool Conclude(const Hypothesis& h, const Evaluated& e, uint32_t basis_number,
                RecognitionStats& stats, RecognizedObject* candidate,
                Correspondences* matches) const;
  // Evaluates `hypotheses` into evaluated_[0 ..) spread over the voting threads when there are
  // two or more and the verifier allows it (else false: the search evaluates each in turn). The
  // scene and `objects` do not change in between, so each evaluation is the one the search
  // would make in turn; the search then concludes them in order.
  bool EvaluateAhead(const Vector<Hypothesis>& hypotheses, const RefineInput& refine_in,
                     const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                     int min_matched);
  // RefineAndVerify of hypotheses[i], from evaluated_[i] when EvaluateAhead ran (`ahead`).
  bool RefineAndVerifyAt(const Vector<Hypothesis>& hypotheses, size_t i, bool ahead,
                         uint32_t basis_number, RefineInput& refine_in,
                         const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                         RecognitionStats& stats, RecognizedObject* candidate,
                         Correspondences* matches, int min_matched = 0);
  // Sets the scene features of `matches` in point_claimed_ / line_claimed_ to `claimed` (1 to
  // mark them, 0 to clear them again).
  void MarkClaims(const Correspondences& matches, const Model& model, uint8_t claimed);
  // The scene bases (indices from `next` on) the competition votes at an object's place, at most
  // compete_bases; returns how many were written to `chosen`.
  int ChooseCompeteBases(uint32_t next, const Eigen::Vector3f& centre_mm, float radius2_mm2,
                         const Correspondences& matches, const Model& model, uint32_t* chosen);
  // Competition at acceptance (RecognizerConfig::compete_bases): `best` (with `best_matches`),
  // about to be accepted from the basis before candidate `next`, is replaced by a clearly better
  // verified object of another model at its place, if the bases near it show one.
  void CompeteAtPlace(uint32_t next, uint32_t basis_number, RefineInput& refine_in,
                      const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                      RecognitionStats& stats, RecognizedObject& best,
                      Correspondences& best_matches);

  TableView table_;
  RecognizerConfig config_;
  VoteTable votes_lut_;
  LineDirectionIndex line_index_;
  float inv_sigma2_point_ = 0, inv_sigma2_line_ = 0;
  float point_reach_mm_ = 0, line_reach_mm_ = 0;
  const Scene* scene_ = nullptr;
  SearchObserver* observer_ = nullptr;

  // Per scene.
  uint8_t point_active_[kMaxScenePoints];
  uint8_t line_active_[kMaxSceneLines];
  // The features the object being accepted matched (CompeteAtPlace): bases made of them only
  // are the ones a larger model under it would be found from.
  uint8_t point_claimed_[kMaxScenePoints];
  uint8_t line_claimed_[kMaxSceneLines];
  Eigen::Vector3f line_dir_[kMaxSceneLines];
  SceneGrid point_grid_;
  SceneState state_;  // the above, for the parts
  SceneTopology topology_;
  BasisCandidates candidates_;
  Eigen::Vector3f grid_scratch_[2 * kMaxSceneLines];
  uint8_t used_left_point_[8192], used_right_point_[8192];  // 2-D feature ids, bit per id
  uint8_t used_left_line_[8192], used_right_line_[8192];

  // Per scene basis: the calling thread's arrays, and those of the other voting threads when
  // voting is spread (SetParallel).
  VoteScratch& ScratchOf(int thread) {
    return thread == 0 ? scratch_ : *other_scratch_[thread - 1];
  }
  VoteScratch scratch_;
  ZeroedPtr<VoteScratch> other_scratch_[kMaxVoteThreads - 1];
  // Bytes at the start of other_scratch_[0] lent (LendVoteScratch): cleared before its next use.
  size_t scratch_lent_bytes_ = 0;
  ParallelFor parallel_;
  int vote_threads_ = 1;
  // Bases voted ahead, by their index in the current pass (valid while the scene and the pass
  // are unchanged).
  AheadVotes ahead_;
  // The hypotheses of one scene basis evaluated at once, in parallel (EvaluateAhead).
  Evaluated evaluated_[kMaxHypothesesPerBasis];
  Vector<RecognizedObject, kMaxDeferredObjects> deferred_;
};

}  // namespace sh
