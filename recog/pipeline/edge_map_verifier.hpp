// The stereo pipeline's acceptance test: a hypothesis is projected into both images and checked
// against their edge pixels (recog/verify), with the objects accepted so far, and those another
// path found, as occluders; a hypothesis sinking into the table is rejected first.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "recog/camera/camera_model.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/verify/edge_refine.hpp"
#include "recog/verify/verify.hpp"
#include "recog/verify/view_camera.hpp"
#include "tables/table_view.hpp"

namespace sh {

// The table the objects stand on, when the installation knows its pose (table.yaml): a
// hypothesis that sinks into it deeper than max_below_mm is rejected before verification.
struct TableConstraint {
  bool known = false;
  RigidTransform left_T_table;  // table frame: z up, top at z = 0
  // Bottom corners triangulate a little below the top, and a tilted object leaning on another
  // may touch the table with an edge: 5 mm is several times the stereo depth error.
  float max_below_mm = 5.0f;
};

// The second look at a hypothesis the image verification rejects narrowly. A pose refined on
// 3-D features can sit a pixel or two off its object's outline, which the verifier's 2.5 px gate
// then misses in one image; fitted to both images' edge pixels (RefinePoseOnEdges, the same
// occluders) and verified again, it is confirmed where it belongs. A wrong model or pose fitted
// to nearby edges gains too, so the fitted pose passes only when confirmed strongly.
struct SecondLook {
  // Both images must confirm at least this share of the visible samples for the fit to be
  // tried; 0: no second look.
  float floor = 0.0f;
  // The fitted pose passes with at least this share in each image (and the verifier's own bar).
  float strong = 0.5f;
  // A hypothesis that passes with under `strong` in either image is fitted to the edge pixels
  // too, and takes the fitted pose when that confirms more in its weaker image.
  bool refit_weak = false;
};

// Checks the ranges (both shares in [0, 1]).
Status CheckSecondLook(const SecondLook& look);

// The verifier of the stereo pipeline: projects the refined hypothesis into both images and
// checks it against their edge pixels, with the objects accepted so far as occluders (the
// kMaxOccluders nearest to the candidate when there are more). Scores go to
// candidate.verify_score = {left, right}.
class EdgeMapVerifier : public HypothesisVerifier {
 public:
  // `hidden` (n_hidden objects, may be null): objects of another path, occluders of every
  // candidate before the accepted ones.
  // `left_grey`/`right_grey`: the images behind the edge maps, for the faint-edge test.
  void Reset(const StereoCalibration* calib, const TableView* table, ConstEdgeMapView left,
             ConstEdgeMapView right, const GreyEvidence& left_grey, const GreyEvidence& right_grey,
             const VerifyConfig* config, const TableConstraint* support, int64_t (*now_ns)(),
             const PosedModel* hidden = nullptr, size_t n_hidden = 0);
  // The second look and the fit it and FitAndVerify use (kept until set again; default: no
  // second look, the default fit).
  void SetSecondLook(const SecondLook& look, const EdgeRefineConfig& fit) {
    look_ = look;
    fit_ = fit;
  }
  bool Verify(const Model& model, const Vector<RecognizedObject>& accepted,
              RecognizedObject& candidate) override;
  // A pose from elsewhere (the one-image rescue's): fitted to both images' edge pixels first,
  // with the occluders the verification uses, then verified (no second look: it is fitted
  // already). *moved tells whether the fit moved it.
  bool FitAndVerify(const Model& model, const Vector<RecognizedObject>& accepted,
                    RecognizedObject& candidate, bool* moved);
  // The verdict depends on the arguments and the frame alone, and the counts are sums: the
  // search verifies a scene basis's hypotheses on the pool's threads at once.
  bool ConcurrentVerify() const override { return true; }
  // Interpenetrate() with each accepted object: either's centre inside the other's box.
  bool Interpenetrates(const Model& model, const RecognizedObject& candidate,
                       const Vector<RecognizedObject>& accepted) const override;

  // Time spent verifying since Reset, summed over the threads that verified.
  int64_t elapsed_ns() const { return elapsed_ns_.load(std::memory_order_relaxed); }
  uint32_t errors() const { return errors_.load(std::memory_order_relaxed); }
  uint32_t below_table() const { return below_table_.load(std::memory_order_relaxed); }
  uint32_t inside_hidden() const { return inside_hidden_.load(std::memory_order_relaxed); }
  // Hypotheses that passed on the second look since Reset.
  uint32_t second_looks() const { return second_looks_.load(std::memory_order_relaxed); }

 private:
  // Verify and FitAndVerify: the occluders gathered once; with `fit_first` the pose is fitted to
  // the edges (*moved, when given, says whether it moved) and gets no second look.
  bool Judge(const Model& model, const Vector<RecognizedObject>& accepted, bool fit_first,
             RecognizedObject& candidate, bool* moved);
  // The checks before any projection: resting on the table, not inside a hidden object.
  bool Admissible(const Model& model, const RecognizedObject& candidate);
  // The occluders of `candidate` into occluders[0, kMaxOccluders); returns their number.
  size_t GatherOccluders(const RecognizedObject& candidate,
                         const Vector<RecognizedObject>& accepted, PosedModel* occluders) const;
  // RefinePoseOnEdges with fit_; true when it replaced *pose.
  bool FitOnEdges(const Model& model, const PosedModel* occluders, size_t n_occluders,
                  RigidTransform* pose) const;
  // The image verification of candidate's pose, its scores into candidate; false on an error.
  bool Score(const Model& model, const PosedModel* occluders, size_t n_occluders,
             RecognizedObject& candidate, VerifyResult* result);
  // Whether a rejection earns the second look (SecondLook::floor).
  bool NearMiss(const VerifyResult& first) const;
  // Fits `fitted`'s pose to the edge pixels (FitOnEdges) and verifies it again: the weaker
  // image's share when it passes, -1 when the fit or the verification fails. `fitted` holds the
  // fitted pose and its scores.
  float FitAndRescore(const Model& model, const PosedModel* occluders, size_t n_occluders,
                      RecognizedObject* fitted);
  // SecondLook::refit_weak for a hypothesis that passed with `first`: the fitted pose and its
  // scores go to `candidate` when its weaker image confirms more; otherwise nothing changes.
  void RefitWeak(const Model& model, const PosedModel* occluders, size_t n_occluders,
                 const VerifyResult& first, RecognizedObject& candidate);
  // The second look (SecondLook); true when it passes, with the fitted pose and its scores in
  // `candidate`.
  bool LookAgain(const Model& model, const PosedModel* occluders, size_t n_occluders,
                 RecognizedObject& candidate);

  const StereoCalibration* calib_ = nullptr;
  const TableView* table_ = nullptr;
  ConstEdgeMapView left_{}, right_{};
  GreyEvidence left_grey_{}, right_grey_{};
  const VerifyConfig* config_ = nullptr;
  const TableConstraint* support_ = nullptr;
  const PosedModel* hidden_ = nullptr;
  size_t n_hidden_ = 0;
  int64_t (*now_ns_)() = nullptr;
  SecondLook look_;
  EdgeRefineConfig fit_;
  // Counts of concurrent calls (ConcurrentVerify).
  std::atomic<int64_t> elapsed_ns_{0};
  std::atomic<uint32_t> errors_{0};
  std::atomic<uint32_t> below_table_{0};
  std::atomic<uint32_t> inside_hidden_{0};
  std::atomic<uint32_t> second_looks_{0};
};

}  // namespace sh
