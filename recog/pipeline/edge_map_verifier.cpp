#include "recog/pipeline/edge_map_verifier.hpp"

#include <algorithm>

#include "recog/pipeline/table_estimate.hpp"
#include "recog/verify/inside_object.hpp"

namespace sh {

void EdgeMapVerifier::Reset(const StereoCalibration* calib, const TableView* table,
                            ConstEdgeMapView left, ConstEdgeMapView right,
                            const GreyEvidence& left_grey, const GreyEvidence& right_grey,
                            const VerifyConfig* config, const TableConstraint* support,
                            int64_t (*now_ns)(), const PosedModel* hidden, size_t n_hidden) {
  calib_ = calib;
  support_ = support;
  hidden_ = hidden;
  n_hidden_ = hidden != nullptr ? n_hidden : 0;
  below_table_ = 0;
  inside_hidden_ = 0;
  table_ = table;
  left_ = left;
  right_ = right;
  left_grey_ = left_grey;
  right_grey_ = right_grey;
  config_ = config;
  now_ns_ = now_ns;
  elapsed_ns_ = 0;
  errors_ = 0;
  second_looks_ = 0;
}

Status CheckSecondLook(const SecondLook& look) {
  if (!(look.floor >= 0.0f && look.floor <= 1.0f) ||
      !(look.strong >= 0.0f && look.strong <= 1.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "second look: floor %g / strong %g outside [0, 1]", look.floor,
                         look.strong);
  }
  return Status::Ok();
}

bool EdgeMapVerifier::Interpenetrates(const Model& model, const RecognizedObject& candidate,
                                      const Vector<RecognizedObject>& accepted) const {
  for (const RecognizedObject& o : accepted) {
    if (Interpenetrate({&model, candidate.cam_T_model}, {&table_->model(o.model), o.cam_T_model})) {
      return true;
    }
  }
  return false;
}

bool EdgeMapVerifier::Admissible(const Model& model, const RecognizedObject& candidate) {
  if (support_ != nullptr && support_->known) {
    if (LowestCornerHeightMm(model, candidate.cam_T_model, support_->left_T_table) <
        -support_->max_below_mm) {
      below_table_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
  }
  // An object another path found already (a colour part's outline, a carton's box edges).
  if (CentreInsideAny(model, candidate.cam_T_model, hidden_, n_hidden_) >= 0) {
    inside_hidden_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

size_t EdgeMapVerifier::GatherOccluders(const RecognizedObject& candidate,
                                        const Vector<RecognizedObject>& accepted,
                                        PosedModel* occluders) const {
  // The hidden objects of another path, then the accepted objects; of each, the ones whose
  // centres are nearest to the candidate when there are more than the slots left (far objects
  // cannot hide it anyway in a table scene).
  size_t n_occluders = 0;
  float dist2[kMaxOccluders];
  const auto add_nearest = [&](const PosedModel& o, size_t first_slot) {
    const float d2 = (o.cam_T_model.t_mm - candidate.cam_T_model.t_mm).squaredNorm();
    size_t slot = n_occluders;
    if (n_occluders == kMaxOccluders) {
      slot =
          static_cast<size_t>(std::max_element(dist2 + first_slot, dist2 + kMaxOccluders) - dist2);
      if (dist2[slot] <= d2) return;
    } else {
      ++n_occluders;
    }
    occluders[slot] = o;
    dist2[slot] = d2;
  };
  for (size_t i = 0; i < n_hidden_; ++i) add_nearest(hidden_[i], 0);
  const size_t first_accepted = n_occluders;
  for (const RecognizedObject& o : accepted) {
    if (first_accepted == kMaxOccluders) break;
    add_nearest({&table_->model(o.model), o.cam_T_model}, first_accepted);
  }
  return n_occluders;
}

bool EdgeMapVerifier::FitOnEdges(const Model& model, const PosedModel* occluders,
                                 size_t n_occluders, RigidTransform* pose) const {
  RigidTransform fitted = *pose;
  EdgeRefineResult fit;
  // An error (never seen: the model and maps were checked) leaves the pose as it was.
  if (!RefinePoseOnEdges(*calib_, left_, right_, model, occluders, n_occluders, fit_, &fitted, &fit)
           .ok() ||
      !fit.refined) {
    return false;
  }
  *pose = fitted;
  return true;
}

bool EdgeMapVerifier::Score(const Model& model, const PosedModel* occluders, size_t n_occluders,
                            RecognizedObject& candidate, VerifyResult* result) {
  const Result<VerifyResult> r =
      VerifyHypothesis(*calib_, left_, right_, {&model, candidate.cam_T_model}, occluders,
                       n_occluders, *config_, left_grey_, right_grey_);
  if (!r.ok()) {
    errors_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  *result = *r;
  candidate.verify_score[0] = r->score_left;
  candidate.verify_score[1] = r->score_right;
  candidate.verify_evidence = float(r->confirmed_left + r->confirmed_right);
  return true;
}

bool EdgeMapVerifier::Verify(const Model& model, const Vector<RecognizedObject>& accepted,
                             RecognizedObject& candidate) {
  return Judge(model, accepted, /*fit_first=*/false, candidate, nullptr);
}

bool EdgeMapVerifier::FitAndVerify(const Model& model, const Vector<RecognizedObject>& accepted,
                                   RecognizedObject& candidate, bool* moved) {
  return Judge(model, accepted, /*fit_first=*/true, candidate, moved);
}

bool EdgeMapVerifier::Judge(const Model& model, const Vector<RecognizedObject>& accepted,
                            bool fit_first, RecognizedObject& candidate, bool* moved) {
  const int64_t start = now_ns_ ? now_ns_() : 0;
  PosedModel occluders[kMaxOccluders];
  const size_t n_occluders = GatherOccluders(candidate, accepted, occluders);
  const bool fitted =
      fit_first && FitOnEdges(model, occluders, n_occluders, &candidate.cam_T_model);
  if (moved != nullptr) *moved = fitted;
  bool passed = false;
  if (Admissible(model, candidate)) {  // the pose as fitted
    VerifyResult first;
    passed = Score(model, occluders, n_occluders, candidate, &first) && first.accepted;
    // A pose fitted to the edges already would be fitted to the same pose again.
    if (!passed && !fit_first && NearMiss(first)) {
      passed = LookAgain(model, occluders, n_occluders, candidate);
    } else if (passed && !fit_first && look_.refit_weak &&
               std::min(first.score_left, first.score_right) < look_.strong) {
      RefitWeak(model, occluders, n_occluders, first, candidate);
    }
  }
  if (now_ns_) elapsed_ns_.fetch_add(now_ns_() - start, std::memory_order_relaxed);
  return passed;
}

bool EdgeMapVerifier::NearMiss(const VerifyResult& first) const {
  // Only a hypothesis both images confirm in part: too few samples or a pose behind a camera
  // is no near miss.
  const bool low_score =
      first.reason == VerifyReason::kLowScoreLeft || first.reason == VerifyReason::kLowScoreRight;
  return look_.floor > 0.0f && low_score &&
         std::min(first.score_left, first.score_right) >= look_.floor;
}

float EdgeMapVerifier::FitAndRescore(const Model& model, const PosedModel* occluders,
                                     size_t n_occluders, RecognizedObject* fitted) {
  VerifyResult again;
  if (!FitOnEdges(model, occluders, n_occluders, &fitted->cam_T_model) ||
      !Score(model, occluders, n_occluders, *fitted, &again) || !again.accepted) {
    return -1.0f;
  }
  return std::min(again.score_left, again.score_right);
}

void EdgeMapVerifier::RefitWeak(const Model& model, const PosedModel* occluders, size_t n_occluders,
                                const VerifyResult& first, RecognizedObject& candidate) {
  RecognizedObject fitted = candidate;
  if (FitAndRescore(model, occluders, n_occluders, &fitted) >
      std::min(first.score_left, first.score_right)) {
    candidate = fitted;
  }
}

bool EdgeMapVerifier::LookAgain(const Model& model, const PosedModel* occluders, size_t n_occluders,
                                RecognizedObject& candidate) {
  RecognizedObject fitted = candidate;
  if (!(FitAndRescore(model, occluders, n_occluders, &fitted) >= look_.strong)) return false;
  candidate = fitted;
  second_looks_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

}  // namespace sh
