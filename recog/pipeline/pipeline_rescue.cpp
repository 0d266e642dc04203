// The pipeline's one-image rescue (PipelineConfig::rescue, docs/pipeline.md stage 4d): the lent
// monocular recogniser searches what the accepted objects leave unexplained in each image, and
// its objects are accepted when the stereo verifier confirms them in both images.
#include <algorithm>
#include <cstring>

#include "recog/mono/aspect.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/verify/inside_object.hpp"

namespace sh {

Status Pipeline::LendRescue(MonoRecognizer* mono) {
  // The one taken back searches on its caller's thread alone again.
  if (rescue_ != nullptr) (void)rescue_->SetParallel(ParallelFor{}, 1);  // cannot fail
  rescue_ = nullptr;
  if (mono == nullptr) return Status::Ok();
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "pipeline: Init() has not succeeded");
  }
  // Objects are reported by model index: the aspect table must list the hash models in order.
  const AspectTableView& aspects = mono->table();
  bool same = aspects.valid() && aspects.model_count() == table_.model_count();
  for (uint32_t m = 0; same && m < table_.model_count(); ++m) {
    same = std::strcmp(aspects.model(m).name, table_.model(m).name) == 0;
  }
  if (!same) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "pipeline: the rescue's aspect table lists other models than the hash "
                         "tables");
  }
  // While lent it evaluates hypotheses on the pool's threads (MonoRecognizer::SetParallel).
  SH_RETURN_IF_ERROR(mono->SetParallel(ParallelOn(&pool_), pool_.threads()));
  rescue_ = mono;
  return Status::Ok();
}

Status Pipeline::Rescue(const Budget& budget, PipelineResult* out) {
  // The stereo recogniser is idle until the next frame: the start of its second vote scratch
  // holds the rescue's second voter's counters meanwhile (when the scratch is smaller, the rescue
  // votes on this thread alone; the stereo recogniser clears what it lent before its next
  // search).
  const bool lent = rescue_->evaluation_threads() > 1;
  if (lent) {
    const Recognizer::LentMemory scratch =
        recognizer_.LendVoteScratch(AspectVoter::CounterBytes(rescue_->table()));
    (void)rescue_->LendVoteCounters(scratch.bytes, scratch.size);
  }
  const Status s = RescueInBothImages(budget, out);
  if (lent) (void)rescue_->LendVoteCounters(nullptr, 0);  // initialised: cannot fail
  return s;
}

Status Pipeline::RescueInBothImages(const Budget& budget, PipelineResult* out) {
  SH_RETURN_IF_ERROR(RescueInImage(0, budget, out));
  if (!config_.rescue.right_image) return Status::Ok();
  // The lent recogniser is set up for the left camera: the right one for this search, then back
  // (which cannot fail: it was the recogniser's camera with this table a moment ago).
  const ViewCamera left = rescue_->camera();
  if (!rescue_->SetCamera(RightView(calib_)).ok()) return Status::Ok();
  const Status s = RescueInImage(1, budget, out);
  (void)rescue_->SetCamera(left);
  return s;
}

Status Pipeline::RescueInImage(int side, const Budget& budget, PipelineResult* out) {
  RescueStats& stats = out->rescue;
  const RescueConfig& rc = config_.rescue;
  if (out->objects.full()) return Status::Ok();
  // What the accepted objects explain leaves the image: their silhouettes join those of the
  // hidden objects (whose corners the extraction dropped already).
  rescue_mask_ = masks_[side];
  const ViewCamera view = side == 0 ? LeftView(calib_) : RightView(calib_);
  for (const RecognizedObject& o : out->objects) {
    (void)rescue_mask_.Add(view, {&table_.model(o.model), o.cam_T_model}, rc.margin_px,
                           rc.corner_radius_px);
  }
  // The gate: enough corners left that no accepted object explains.
  uint32_t& free_corners = side == 0 ? stats.free_corners : stats.free_corners_right;
  for (const Corner2D& c : features_[side].corners) {
    free_corners += rescue_mask_.Hides(c.x_px, c.y_px) ? 0u : 1u;
  }
  if (free_corners < static_cast<uint32_t>(std::max(0, rc.min_free_corners))) {
    return Status::Ok();
  }
  stats.ran = true;
  if (side == 1) stats.ran_right = true;
  rescue_objects_.clear();
  for (const RecognizedObject& o : out->objects) (void)rescue_objects_.push_back(o);
  const size_t n_known = rescue_objects_.size();
  Budget limited = budget;
  limited.max_objects = 0;
  limited.max_scene_bases = std::min(budget.max_scene_bases, rc.max_scene_bases);
  // A recogniser set up without a table takes the frame's estimated or carried one for this
  // search (objects resting on it: depth and tilt fixed), and is given back as it was.
  const bool lend_plane = frame_table_.known && !rescue_->has_table();
  if (lend_plane && !rescue_->SetTable(&frame_table_.left_T_table).ok()) {
    stats.ran = false;  // a plane the camera is not above: no search on it
    return Status::Ok();
  }
  const Status searched =
      rescue_->RecognizeRest(features_[side], rescue_mask_, limited, rescue_objects_, n_known,
                             side == 0 ? &stats.search : &stats.search_right);
  if (lend_plane) (void)rescue_->SetTable(nullptr);  // no table: cannot fail
  SH_RETURN_IF_ERROR(searched);
  for (size_t i = n_known; i < rescue_objects_.size(); ++i) {
    ++stats.found;
    RecognizedObject candidate = rescue_objects_[i];
    // Models the active set leaves out (RecognizerConfig::model_mask) are not reported.
    if (!((config_.recognizer.model_mask >> candidate.model) & 1u)) continue;
    const Model& model = table_.model(candidate.model);
    if (frame_table_.known) {
      const float lowest =
          LowestCornerHeightMm(model, candidate.cam_T_model, frame_table_.left_T_table);
      if (!(lowest <= rc.max_above_table_mm)) {  // the verifier checks the other side
        ++stats.refused_rest;
        continue;
      }
    } else {
      const Eigen::Vector3f centre = candidate.cam_T_model * ModelCentroid(model);
      if (!config_.stereo.volume.Contains(centre.cast<double>())) {
        ++stats.refused_rest;
        continue;
      }
    }
    bool overlaps = false;
    for (const RecognizedObject& o : out->objects) {
      overlaps = overlaps || Interpenetrate({&model, candidate.cam_T_model},
                                            {&table_.model(o.model), o.cam_T_model});
    }
    if (overlaps) {
      ++stats.refused_overlap;
      continue;
    }
    // The stereo verifier: both images, its thresholds, the accepted objects as occluders, the
    // table check. One image's search is weaker evidence than the stereo search's: what the
    // stereo search would hold back as weakly confirmed (RecognizerConfig::defer_below_score) is
    // not taken from it.
    const uint32_t below = verifier_.below_table();
    bool moved = false;
    const bool verified = rc.edge_fit
                              ? verifier_.FitAndVerify(model, out->objects, candidate, &moved)
                              : verifier_.Verify(model, out->objects, candidate);
    stats.edge_fitted += moved ? 1u : 0u;
    if (!verified || std::min(candidate.verify_score[0], candidate.verify_score[1]) <
                         config_.recognizer.defer_below_score) {
      if (verifier_.below_table() != below) {
        ++stats.refused_rest;
      } else {
        ++stats.refused_verify;
      }
      continue;
    }
    candidate.instance = 0;
    for (const RecognizedObject& o : out->objects) candidate.instance += o.model == candidate.model;
    if (!out->objects.push_back(candidate)) break;
    ++stats.added;
  }
  return Status::Ok();
}

}  // namespace sh
