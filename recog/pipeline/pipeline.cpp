#include "recog/pipeline/pipeline.hpp"

#include <algorithm>

#include "recog/camera/calibration_check.hpp"
#include "recog/camera/image_check.hpp"
#include "recog/stereo/image_adapters.hpp"
#include "recog/verify/inside_object.hpp"

namespace sh {
namespace {

ConstEdgeMapView AsConst(const EdgeMapView& v) { return {v.edge, v.orientation}; }

}  // namespace

const char* TableSourceName(TableSource s) {
  switch (s) {
    case TableSource::kNone:
      return "none";
    case TableSource::kGiven:
      return "file";
    case TableSource::kEstimated:
      return "estimated";
    case TableSource::kCarried:
      return "carried";
  }
  return "unknown";
}

Status Pipeline::Init(const StereoCalibration& calib, const TableView& table,
                      const PipelineConfig& config, ClockFn now_ns,
                      const ShapeViewsView* shape_views) {
  initialised_ = false;
  // Lent for one calibration and table: taken back (its pool too), lent again after Init.
  (void)LendRescue(nullptr);  // with no recogniser it cannot fail
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
  if (calib.left.width > kMaxImageWidth || calib.left.height > kMaxImageHeight ||
      calib.right.width > kMaxImageWidth || calib.right.height > kMaxImageHeight) {
    return Status::Error(StatusCode::kOutOfRange,
                         "calibration image size %dx%d / %dx%d exceeds the supported %dx%d",
                         calib.left.width, calib.left.height, calib.right.width, calib.right.height,
                         kMaxImageWidth, kMaxImageHeight);
  }
  SH_RETURN_IF_ERROR(InitImageBuffers(calib, config.rgb_frames));
  table_ = table;  // the model set refers to the pipeline's own copy of the view
  models_ = ModelSet(&table_, shape_views);
  if (models_.count() == 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "pipeline: neither the hash tables nor a view database hold models");
  }
  if (models_.hash_count() > 0) {
    SH_RETURN_IF_ERROR(ValidateFeatureConfig(config.features));
    SH_RETURN_IF_ERROR(CheckVerifyConfig(config.verify));
    SH_RETURN_IF_ERROR(CheckSecondLook(config.second_look));
    SH_RETURN_IF_ERROR(stereo_.Configure(calib, config.stereo));
    SH_RETURN_IF_ERROR(recognizer_.Init(table, config.recognizer));
    SH_RETURN_IF_ERROR(CheckTableEstimateConfig(config.table_estimate));
    SH_RETURN_IF_ERROR(CheckTableCarryConfig(config.table_carry));
  }
  shape_enabled_ = models_.shape_count() > 0;
  if (shape_enabled_) {
    if (shape_ == nullptr) shape_ = MakeZeroed<ShapeRecognizer>();  // start-up, not per frame
    if (shape_ == nullptr) {
      return Status::Error(StatusCode::kUnavailable,
                           "pipeline: cannot allocate the colour path's %zu bytes",
                           sizeof(ShapeRecognizer));
    }
    SH_RETURN_IF_ERROR(shape_->Init(calib, *shape_views, config.shape,
                                    static_cast<uint16_t>(models_.shape_offset()), now_ns));
  } else {
    shape_.reset();
  }
  SH_RETURN_IF_ERROR(pool_.Start(config.threads));
  if (models_.hash_count() > 0) {
    // The search votes on the pool's threads when it has more than one (Recognizer::SetParallel).
    SH_RETURN_IF_ERROR(recognizer_.SetParallel(ParallelOn(&pool_), pool_.threads()));
  }
  // The colour path refines a seed's candidates on them too.
  if (shape_enabled_) shape_->SetParallel(ParallelOn(&pool_), pool_.threads());
  calib_ = calib;
  config_ = config;
  verifier_.SetSecondLook(config.second_look, config.edge_refine_config);
  now_ns_ = now_ns;
  carry_.Reset();  // another calibration or table may mean another cell
  initialised_ = true;
  return Status::Ok();
}

Status Pipeline::InitImageBuffers(const StereoCalibration& calib, bool rgb_frames) {
  const CameraIntrinsics* cams[2] = {&calib.left, &calib.right};
  for (int i = 0; i < 2; ++i) {
    const Status st = workspace_[i].Init(cams[i]->width, cams[i]->height);
    if (!st.ok()) return Status::Error(st.code(), "pipeline: %s", st.message());
  }
  if (!rgb_frames) {
    grey_block_ = InitBlock();
    for (int i = 0; i < 2; ++i) {
      grey_[i] = nullptr;
      grey_width_[i] = grey_height_[i] = 0;
    }
    return Status::Ok();
  }
  if (grey_width_[0] == calib.left.width && grey_height_[0] == calib.left.height &&
      grey_width_[1] == calib.right.width && grey_height_[1] == calib.right.height) {
    return Status::Ok();
  }
  size_t pixels[2];
  for (int i = 0; i < 2; ++i) {
    pixels[i] = static_cast<size_t>(cams[i]->width) * static_cast<size_t>(cams[i]->height);
    grey_width_[i] = grey_height_[i] = 0;
  }
  const size_t bytes =
      InitBlock::PieceBytes<uint8_t>(pixels[0]) + InitBlock::PieceBytes<uint8_t>(pixels[1]);
  if (!grey_block_.Allocate(bytes)) {
    return Status::Error(StatusCode::kUnavailable, "pipeline: cannot allocate %zu bytes of grey",
                         bytes);
  }
  for (int i = 0; i < 2; ++i) {
    grey_[i] = grey_block_.Take<uint8_t>(pixels[i]);
    grey_width_[i] = cams[i]->width;
    grey_height_[i] = cams[i]->height;
  }
  return Status::Ok();
}

void Pipeline::ExtractOne(void* self, int image) {
  Pipeline& p = *static_cast<Pipeline*>(self);
  const HiddenMask& mask = p.masks_[image];
  p.frame_status_[image] =
      ExtractFeatures(p.frame_images_[image], p.config_.features, p.workspace_[image],
                      p.features_[image], mask.size() > 0 ? &mask : nullptr);
}

void Pipeline::BuildMasks(const PosedModel* hidden, size_t n_hidden, PipelineResult* out) {
  const ViewCamera views[2] = {LeftView(calib_), RightView(calib_)};
  for (int i = 0; i < 2; ++i) masks_[i].Clear();
  for (size_t k = 0; k < n_hidden; ++k) {
    bool both = true;
    for (int i = 0; i < 2; ++i) {
      both = masks_[i].Add(views[i], hidden[k], config_.hide_margin_px) && both;
    }
    if (both) {
      ++out->hidden_objects;
    } else {
      ++out->hidden_not_masked;
    }
  }
}

float Pipeline::MsSince(int64_t start_ns) const {
  // Nanoseconds to milliseconds; frame times fit a float's 24 bits many times over.
  return now_ns_ ? static_cast<float>(now_ns_() - start_ns) * 1e-6f : 0.0f;
}

Status Pipeline::Process(ConstGrayView left, ConstGrayView right, float budget_ms,
                         PipelineResult* out, const PosedModel* hidden, size_t n_hidden) {
  return Process(FrameView::Gray(left), FrameView::Gray(right), budget_ms, out, hidden, n_hidden);
}

Status Pipeline::Process(const FrameView& left, const FrameView& right, float budget_ms,
                         PipelineResult* out, const PosedModel* hidden, size_t n_hidden) {
  if (out == nullptr) return Status::Error(StatusCode::kInvalidArgument, "pipeline: no result");
  out->objects.clear();
  *out = PipelineResult{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition, "pipeline: Init() has not succeeded");
  }
  const FrameView frames[2] = {left, right};
  for (int i = 0; i < 2; ++i) {
    const char* which = i == 0 ? "left" : "right";
    const CameraIntrinsics& cam = i == 0 ? calib_.left : calib_.right;
    const Status checked = CheckFrame(frames[i]);
    if (!checked.ok()) return Status::Error(checked.code(), "%s %s", which, checked.message());
    if (frames[i].width() != cam.width || frames[i].height() != cam.height) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s image is %dx%d but the calibration says %dx%d", which,
                           frames[i].width(), frames[i].height(), cam.width, cam.height);
    }
  }
  const int64_t t0 = now_ns_ ? now_ns_() : 0;
  // The colour parts first (segmentation, view search and refinement are not interruptible; the
  // polyhedral search is the anytime part and gets what is left of the budget). What they find
  // is hidden from the polyhedral path beside the caller's objects.
  shape_objects_.clear();
  if (shape_enabled_ && left.has_colour() && right.has_colour()) {
    SH_RETURN_IF_ERROR(shape_->Process(left, right, shape_objects_, &out->shape));
  }
  size_t n_all = 0;
  const size_t n_given = hidden != nullptr ? n_hidden : 0;
  for (size_t i = 0; i < n_given + shape_objects_.size(); ++i) {
    if (n_all == kMaxHiddenObjects) {
      ++out->hidden_not_masked;  // capacity: hidden neither from the features nor the search
      continue;
    }
    if (i < n_given) {
      hidden_[n_all++] = hidden[i];
    } else {
      const RecognizedObject& o = shape_objects_[i - n_given];
      hidden_[n_all++] = {&models_.model(o.model), o.cam_T_model};
      ++out->hidden_colour_parts;
    }
  }
  if (models_.hash_count() > 0) {
    ConstGrayView grey[2];
    for (int i = 0; i < 2; ++i) {
      if (FrameLuma(frames[i], &grey[i])) continue;
      if (grey_[i] == nullptr) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "pipeline: the %s frame is RGB, but the pipeline was set up for "
                             "frames with a luma plane (rgb_frames off)",
                             i == 0 ? "left" : "right");
      }
      // RGB: the grey the polyhedral path reads, converted once (the image fits kMaxImage*).
      const GrayView g{grey_[i], frames[i].width(), frames[i].height(), frames[i].width()};
      SH_RETURN_IF_ERROR(FrameToGray(frames[i], g));
      grey[i] = g;
    }
    SH_RETURN_IF_ERROR(CheckImageFitsCamera(grey[0], calib_.left, "left"));
    SH_RETURN_IF_ERROR(CheckImageFitsCamera(grey[1], calib_.right, "right"));
    const int64_t t1 = now_ns_ ? now_ns_() : 0;
    SH_RETURN_IF_ERROR(
        RecognisePolyhedra(grey[0], grey[1], budget_ms, t0, t1, hidden_, n_all, out));
  }
  for (const RecognizedObject& o : shape_objects_) {
    if (!out->objects.push_back(o)) {
      out->shape.objects_full = true;
      break;
    }
  }
  if (now_ns_) out->time.total_ms = MsSince(t0);
  return Status::Ok();
}

Status Pipeline::RecognisePolyhedra(ConstGrayView left, ConstGrayView right, float budget_ms,
                                    int64_t frame_t0, int64_t t0, const PosedModel* hidden,
                                    size_t n_hidden, PipelineResult* out) {
  // 1. Per-image features, the two images in parallel when the pool has two threads, without
  // the silhouettes of the hidden objects.
  BuildMasks(hidden, n_hidden, out);
  frame_images_[0] = left;
  frame_images_[1] = right;
  pool_.ParallelFor(2, &Pipeline::ExtractOne, this);
  size_t n_points[2], n_lines[2];
  for (int i = 0; i < 2; ++i) {
    const Status& s = frame_status_[i];
    if (!s.ok()) return s.WithContext("%s image", i == 0 ? "left" : "right");
    n_points[i] = ToStereoPoints(features_[i].corners, stereo_points_[i]);
    n_lines[i] = ToStereoLines(features_[i].lines, stereo_lines_[i]);
    out->points2d[i] = static_cast<uint32_t>(n_points[i]);
    out->lines2d[i] = static_cast<uint32_t>(n_lines[i]);
    out->detection[i] = features_[i].chosen;
    out->masked_corners[i] = features_[i].masked_corners;
    out->masked_edge_pixels[i] = features_[i].masked_edge_pixels;
  }
  const int64_t t1 = now_ns_ ? now_ns_() : 0;
  out->time.features_ms = MsSince(t0);

  // 2. Sloppy stereo. A full scene is a defined truncation: recognise what fits.
  scene_.clear();
  PointStereoStats point_stats;
  LineStereoStats line_stats;
  Status s = stereo_.MatchPoints(stereo_points_[0], n_points[0], stereo_points_[1], n_points[1],
                                 scene_.points, &point_stats);
  if (!s.ok() && s.code() != StatusCode::kResourceExhausted) return s;
  s = stereo_.MatchLines(stereo_lines_[0], n_lines[0], stereo_lines_[1], n_lines[1], scene_.lines,
                         &line_stats);
  if (!s.ok() && s.code() != StatusCode::kResourceExhausted) return s;
  out->points3d = static_cast<uint32_t>(scene_.points.size());
  out->lines3d = static_cast<uint32_t>(scene_.lines.size());
  out->points3d_truncated = point_stats.truncated;
  out->lines3d_truncated = line_stats.truncated;
  const int64_t t2 = now_ns_ ? now_ns_() : 0;
  out->time.stereo_ms = MsSince(t1);

  // 3-5. Hashing, pose refinement and verification against both edge maps, with the given table
  // when there is one.
  frame_table_ = config_.table;
  out->table_source = config_.table.known ? TableSource::kGiven : TableSource::kNone;
  Budget budget;
  if (budget_ms > 0 && now_ns_ != nullptr) {
    // The budget covers the whole frame: recognition gets what features and stereo left.
    budget.deadline_ns = frame_t0 + static_cast<int64_t>(static_cast<double>(budget_ms) * 1e6);
    budget.now_ns = now_ns_;
  }
  int64_t verify_ns = 0;
  const TableEstimateConfig& estimate = config_.table_estimate;
  const bool estimating = !config_.table.known && estimate.enabled;
  const bool carrying = estimating && config_.table_carry.enabled;
  if (carrying && carry_.Next(config_.table_carry) == TableCarryUse::kCarry) {
    SH_RETURN_IF_ERROR(UseCarriedTable(budget, hidden, n_hidden, out, &verify_ns));
  } else {
    SH_RETURN_IF_ERROR(EstimateAndSearch(budget, hidden, n_hidden, out, &verify_ns));
    if (carrying) carry_.ObserveEstimate(config_.table_carry, out->table_estimate);
  }
  out->table_carry = carry_;
  int64_t t3 = now_ns_ ? now_ns_() : 0;
  if (now_ns_) {
    const float recognize_ms = MsSince(t2);
    out->time.verify_ms = static_cast<float>(verify_ns) * 1e-6f;
    out->time.hashing_ms = std::max(0.0f, recognize_ms - out->time.verify_ms - out->time.table_ms);
  }

  // 5c. What stereo missed, from the left image alone, confirmed in both.
  if (rescue_ != nullptr && config_.rescue.enabled) {
    SH_RETURN_IF_ERROR(Rescue(budget, out));
    if (now_ns_) {
      out->time.rescue_ms = MsSince(t3);
      t3 = now_ns_();
    }
  }

  // 6. The last fit: each accepted pose to the edge pixels of both images.
  RefineOnEdges(hidden, n_hidden, out);
  DropInsideHidden(hidden, n_hidden, out);
  if (now_ns_) out->time.refine_ms = MsSince(t3);
  return Status::Ok();
}

Status Pipeline::EstimateAndSearch(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                                   PipelineResult* out, int64_t* verify_ns) {
  const TableEstimateConfig& estimate = config_.table_estimate;
  const bool estimating = !config_.table.known && estimate.enabled;
  // A first search that only has to find the objects for the plane can stop early.
  Budget first = budget;
  if (estimating && estimate.search_again) first.max_objects = estimate.first_search_objects;
  SH_RETURN_IF_ERROR(Search(first, hidden, n_hidden, out, verify_ns));
  if (!estimating) return Status::Ok();
  // 5b. Without a given table, the plane the objects found rest on (table_estimate.hpp).
  SH_RETURN_IF_ERROR(UseEstimatedTable(budget, hidden, n_hidden, out, verify_ns));
  const bool cut_short = first.max_objects != 0 && out->recognition.accepted >= first.max_objects;
  if (out->table_source != TableSource::kEstimated && cut_short) {
    // No table after all: the first search runs to its end, as it would have without one.
    SH_RETURN_IF_ERROR(SearchAgain(budget, hidden, n_hidden, out, verify_ns));
  }
  return Status::Ok();
}

Status Pipeline::UseCarriedTable(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                                 PipelineResult* out, int64_t* verify_ns) {
  // As with a given table: the space over it and one search with the table check.
  frame_table_.known = true;
  frame_table_.left_T_table = carry_.left_T_table();
  out->table_source = TableSource::kCarried;
  KeepOverFrameTable(out);
  SH_RETURN_IF_ERROR(Search(budget, hidden, n_hidden, out, verify_ns));
  // The check: do the objects found rest on it, did hypotheses sink into it.
  const Model* models[kMaxObjects];
  const size_t n = std::min(out->objects.size(), kMaxObjects);
  for (size_t i = 0; i < n; ++i) models[i] = &table_.model(out->objects[i].model);
  out->table_resting = CountResting(out->objects.data(), models, n, frame_table_.left_T_table,
                                    config_.table_estimate.tolerance_mm);
  carry_.ObserveCarried(config_.table_carry, static_cast<uint32_t>(n), out->table_resting,
                        out->below_table);
  return Status::Ok();
}

void Pipeline::KeepOverFrameTable(PipelineResult* out) {
  const int64_t keep_start = now_ns_ ? now_ns_() : 0;
  out->table_dropped = KeepOverTable(frame_table_.left_T_table, kTableVolumeBelowMm,
                                     kTableVolumeHeightMm, config_.stereo.min_overlap_mm, &scene_);
  out->points3d = static_cast<uint32_t>(scene_.points.size());
  out->lines3d = static_cast<uint32_t>(scene_.lines.size());
  if (now_ns_) out->time.table_ms += MsSince(keep_start);
}

void Pipeline::DropInsideHidden(const PosedModel* hidden, size_t n_hidden, PipelineResult* out) {
  size_t kept = 0;
  for (size_t i = 0; i < out->objects.size(); ++i) {
    const RecognizedObject& o = out->objects[i];
    if (CentreInsideAny(table_.model(o.model), o.cam_T_model, hidden, n_hidden) >= 0) {
      ++out->inside_hidden;
      continue;
    }
    out->objects[kept++] = o;
  }
  (void)out->objects.resize(kept);
}

Status Pipeline::Search(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                        PipelineResult* out, int64_t* verify_ns) {
  verifier_.Reset(&calib_, &table_, AsConst(features_[0].edges), AsConst(features_[1].edges),
                  grey_evidence(0), grey_evidence(1), &config_.verify, &frame_table_, now_ns_,
                  hidden, n_hidden);
  const Status s =
      recognizer_.Recognize(scene_, verifier_, budget, out->objects, &out->recognition);
  out->verify_errors += verifier_.errors();
  out->below_table += verifier_.below_table();
  out->inside_hidden += verifier_.inside_hidden();
  out->second_looks += verifier_.second_looks();
  *verify_ns += verifier_.elapsed_ns();
  return s;
}

Status Pipeline::SearchAgain(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                             PipelineResult* out, int64_t* verify_ns) {
  const RecognitionStats first = out->recognition;
  SH_RETURN_IF_ERROR(Search(budget, hidden, n_hidden, out, verify_ns));
  // The work of both searches.
  out->recognition.scene_bases_tried += first.scene_bases_tried;
  out->recognition.hypotheses += first.hypotheses;
  out->recognition.verifications += first.verifications;
  return Status::Ok();
}

Status Pipeline::UseEstimatedTable(const Budget& budget, const PosedModel* hidden, size_t n_hidden,
                                   PipelineResult* out, int64_t* verify_ns) {
  const int64_t start = now_ns_ ? now_ns_() : 0;
  const Model* models[kMaxObjects];
  const size_t n = std::min(out->objects.size(), kMaxObjects);
  for (size_t i = 0; i < n; ++i) models[i] = &table_.model(out->objects[i].model);
  EstimateTableFromObjects(out->objects.data(), models, n, config_.table_estimate,
                           &out->table_estimate);
  if (now_ns_) out->time.table_ms = MsSince(start);
  if (!out->table_estimate.accepted()) return Status::Ok();
  frame_table_.known = true;
  frame_table_.left_T_table = out->table_estimate.left_T_table;
  out->table_source = TableSource::kEstimated;
  if (config_.table_estimate.search_again) {
    // What a given table does, now with the estimate: the features under the table and far over
    // it leave the scene (WorkingVolume::OverTable), and the search runs again with the table
    // check. Its objects replace the first search's.
    KeepOverFrameTable(out);
    return SearchAgain(budget, hidden, n_hidden, out, verify_ns);
  }
  // The table check on the objects found: those sunk into the plane the others rest on go.
  size_t kept = 0;
  for (size_t i = 0; i < out->objects.size(); ++i) {
    const RecognizedObject& o = out->objects[i];
    if (LowestCornerHeightMm(table_.model(o.model), o.cam_T_model, frame_table_.left_T_table) <
        -frame_table_.max_below_mm) {
      ++out->below_table;
      continue;
    }
    out->objects[kept++] = o;
  }
  (void)out->objects.resize(kept);
  return Status::Ok();
}

void Pipeline::RefineOnEdges(const PosedModel* hidden, size_t n_hidden, PipelineResult* out) {
  for (RecognizedObject& o : out->objects) {
    o.cam_T_model_features = o.cam_T_model;
    o.edge_refined = false;
  }
  if (!config_.edge_refine) return;
  // Each object is fitted with the others at their feature poses as occluders, so the fits are
  // independent of each other and of their order: the pool runs them in parallel, each writing
  // only its own object's pose, and the results do not depend on the thread count.
  refine_hidden_ = hidden;
  refine_n_hidden_ = n_hidden;
  refine_out_ = out;
  pool_.ParallelFor(static_cast<int>(out->objects.size()), &Pipeline::RefineOne, this);
}

void Pipeline::RefineOne(void* self, int index) {
  Pipeline& p = *static_cast<Pipeline*>(self);
  PipelineResult& out = *p.refine_out_;
  const auto i = static_cast<size_t>(index);
  PosedModel occluders[kMaxOccluders];
  size_t n_occluders = 0;
  for (size_t j = 0; j < p.refine_n_hidden_ && n_occluders < kMaxOccluders; ++j) {
    occluders[n_occluders++] = p.refine_hidden_[j];
  }
  for (size_t j = 0; j < out.objects.size() && n_occluders < kMaxOccluders; ++j) {
    if (j == i) continue;
    occluders[n_occluders++] = {&p.table_.model(out.objects[j].model),
                                out.objects[j].cam_T_model_features};
  }
  RecognizedObject& o = out.objects[i];
  EdgeRefineResult r;
  RigidTransform pose = o.cam_T_model_features;
  const Status s = RefinePoseOnEdges(
      p.calib_, AsConst(p.features_[0].edges), AsConst(p.features_[1].edges),
      p.table_.model(o.model), occluders, n_occluders, p.config_.edge_refine_config, &pose, &r);
  // Only this object's pose is written; the others read cam_T_model_features. An error (never
  // seen: the model and maps were checked) keeps the feature pose.
  if (s.ok() && r.refined) {
    o.cam_T_model = pose;
    o.edge_refined = true;
  }
}

ConstEdgeMapView Pipeline::left_edges() const { return AsConst(features_[0].edges); }
ConstEdgeMapView Pipeline::right_edges() const { return AsConst(features_[1].edges); }
const Scene& Pipeline::scene() const { return scene_; }
const TableView& Pipeline::table() const { return table_; }
const StereoCalibration& Pipeline::calibration() const { return calib_; }

}  // namespace sh
