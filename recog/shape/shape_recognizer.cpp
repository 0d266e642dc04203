#include "recog/shape/shape_recognizer.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/camera/calibration_check.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {
namespace {

constexpr size_t kNearestPerImage = 32;  // raw nearest views before size check and diversity

ViewCamera Camera(const StereoCalibration& calib, int i) {
  return i == 0 ? LeftView(calib) : RightView(calib);
}

}  // namespace

ShapeRefineConfig CoarseRefine() {
  ShapeRefineConfig c;
  c.sample_step_px = 6.0f;
  c.iterations = 4;
  c.search_start_px = 12.0f;
  c.search_end_px = 6.0f;
  c.visibility_every = 4;
  return c;
}

ShapeRefineConfig FineRefine() {
  ShapeRefineConfig c;
  c.iterations = 8;
  c.search_start_px = 6.0f;
  c.search_end_px = 3.0f;
  return c;
}

Status CheckShapeConfig(const ShapeConfig& c) {
  SH_RETURN_IF_ERROR(CheckSegmentConfig(c.segment));
  SH_RETURN_IF_ERROR(CheckRegionPairConfig(c.pairs));
  SH_RETURN_IF_ERROR(CheckShapeRefineConfig(c.coarse));
  SH_RETURN_IF_ERROR(CheckShapeRefineConfig(c.refine));
  const bool ok = c.views_per_image >= 1 && c.fine_hypotheses >= 1 &&
                  2 * static_cast<size_t>(c.views_per_image) <= kMaxShapeCandidates &&
                  c.diverse_deg >= 0 && c.diverse_deg <= 180 && c.max_extent_ratio >= 1 &&
                  c.corrective_iterations >= 0 && c.corrective_iterations <= 20 &&
                  c.min_edge_score >= 0 && c.min_edge_score <= 1 && c.max_background_share >= 0 &&
                  c.max_background_share <= 1 && c.explained_share > 0 && c.explained_share <= 1;
  if (!ok) {
    return Status::Error(StatusCode::kOutOfRange,
                         "shape recognition: settings out of range (1..%zu views per image, "
                         "shares in 0..1, extent ratio >= 1, 0..20 corrective iterations)",
                         kMaxShapeCandidates / 2);
  }
  return Status::Ok();
}

Status ShapeRecognizer::Init(const StereoCalibration& calib, const ShapeViewsView& views,
                             const ShapeConfig& config, uint16_t model_id_offset, ClockFn now_ns) {
  initialised_ = false;
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
  SH_RETURN_IF_ERROR(CheckShapeConfig(config));
  if (views.empty()) {
    return Status::Error(StatusCode::kInvalidArgument, "shape recognition: no view database");
  }
  float kd[kMaxShapeModels][3];
  for (uint32_t m = 0; m < views.model_count(); ++m) {
    for (int k = 0; k < 3; ++k) kd[m][k] = views.shape_model(m).kd[k];
  }
  ColourClassSet classes;
  const Status s =
      DeriveColourClasses(kd, static_cast<int>(views.model_count()), &classes, colour_of_model_);
  if (!s.ok()) return Status::Error(s.code(), "shape recognition: %s", s.message());
  SH_RETURN_IF_ERROR(classifier_.Init(classes));
  calib_ = calib;
  views_ = views;
  config_ = config;
  model_id_offset_ = model_id_offset;
  now_ns_ = now_ns;
  initialised_ = true;
  return Status::Ok();
}

float ShapeRecognizer::MsSince(int64_t start) const {
  // Nanoseconds to milliseconds.
  return now_ns_ ? static_cast<float>(now_ns_() - start) * 1e-6f : 0.0f;
}

bool ShapeRecognizer::RegionWindow(int camera, const ColourRegion& region, ShapeWindow* window) {
  const GrayView mask{region_mask_, region.width(), region.height(), region.width()};
  RegionMask(region, segmentation_[camera].runs(), mask);
  return ComputeShapeWindow(mask, window_scratch_, window).ok();
}

void ShapeRecognizer::Candidates(const RegionPair& pair, Vector<Candidate>& out) {
  out.clear();
  const ColourRegion* regions[2] = {&segmentation_[0].regions()[pair.left],
                                    &segmentation_[1].regions()[pair.right]};
  const uint8_t colour = regions[0]->colour;
  uint32_t mask = 0;
  for (uint32_t m = 0; m < views_.model_count(); ++m) {
    if (colour_of_model_[m] == colour) mask |= 1u << m;
  }
  for (int cam = 0; cam < 2; ++cam) {
    const ColourRegion& region = *regions[cam];
    ShapeWindow window{};
    if (!RegionWindow(cam, region, &window)) continue;
    ShapeCoefficients coefficients;
    views_.Project(window, &coefficients);
    Vector<ViewMatch, kNearestPerImage> nearest;
    views_.Nearest(coefficients, mask, kNearestPerImage, nearest);
    // The part's centre in this camera: depth for the size check, ray frame for orientation.
    const ViewCamera view = Camera(calib_, cam);
    const Eigen::Vector3f centre = view.cam_T_left * pair.centroid_mm;
    const CameraIntrinsics& ci = view.intrinsics;
    // A region cut by the image border is smaller than its part: no size check then.
    const bool clipped =
        region.x0 == 0 || region.y0 == 0 || region.x1 == ci.width - 1 || region.y1 == ci.height - 1;
    // Box size in pixels -> millimetres at the part's depth.
    const float extent[2] = {static_cast<float>(region.width()) * centre.z() / float(ci.fx),
                             static_cast<float>(region.height()) * centre.z() / float(ci.fy)};
    const Eigen::Matrix3f left_R_ray = view.cam_T_left.R.transpose() * RayFrame(centre);
    int taken = 0;
    for (const ViewMatch& match : nearest) {
      if (taken == config_.views_per_image) break;
      const ShapeViewRecord& rec = views_.view(match.view);
      if (!clipped) {
        bool fits = true;
        for (int k = 0; k < 2; ++k) {
          const float e = UQExtentMm::FromRaw(rec.extent_mm[k]).ToFloat();
          fits &= e <= config_.max_extent_ratio * extent[k] &&
                  extent[k] <= config_.max_extent_ratio * e;
        }
        if (!fits) continue;
      }
      Candidate c{rec.model, left_R_ray * views_.ViewRotation(match.view)};
      bool diverse = true;
      for (const Candidate& other : out) {
        if (other.model == c.model &&
            RotationAngleDeg(other.cam_R_model.transpose() * c.cam_R_model) < config_.diverse_deg) {
          diverse = false;
          break;
        }
      }
      if (!diverse) continue;
      if (!out.push_back(c)) return;
      ++taken;
    }
  }
}

void ShapeRecognizer::InitialPose(const RegionPair& pair, PosedModel* object) {
  // Orientation relative to the viewing ray stays as the view gave it while the position moves.
  const Eigen::Matrix3f ray_R_model =
      RayFrame(pair.centroid_mm).transpose() * object->cam_T_model.R;
  object->cam_T_model.t_mm = pair.centroid_mm;
  const ColourRegion* regions[2] = {&segmentation_[0].regions()[pair.left],
                                    &segmentation_[1].regions()[pair.right]};
  for (int it = 0; it < config_.corrective_iterations; ++it) {
    object->cam_T_model.R = RayFrame(object->cam_T_model.t_mm) * ray_R_model;
    Eigen::Vector2d target[2];
    bool ok = true;
    for (int cam = 0; cam < 2 && ok; ++cam) {
      const ViewCamera view = Camera(calib_, cam);
      SilhouetteMask mask;
      Eigen::Vector2d origin;
      ok = RasterizeSilhouette(view, *object, silhouette_scratch_, &mask).ok() && !mask.empty() &&
           ProjectToPixel(view.intrinsics,
                          (view.cam_T_left * object->cam_T_model.t_mm).cast<double>(), &origin);
      if (!ok) break;
      // Where the origin must project for the predicted centroid to meet the observed one.
      target[cam] =
          origin + Eigen::Vector2d(regions[cam]->cx - mask.cx, regions[cam]->cy - mask.cy);
    }
    RayMidpoint mid;
    if (!ok || !TriangulatePixels(calib_, target[0], target[1], &mid) || !(mid.depth_a_mm > 0)) {
      break;
    }
    object->cam_T_model.t_mm = mid.p_mm.cast<float>();
  }
  object->cam_T_model.R = RayFrame(object->cam_T_model.t_mm) * ray_R_model;
}

ShapeRecognizer::Verdict ShapeRecognizer::Evaluate(const PosedModel& object, uint8_t colour,
                                                   const ShapeRefineResult& fit) {
  Verdict v;
  v.accepted = true;
  for (int cam = 0; cam < 2; ++cam) {
    v.edge_score[cam] = fit.fit[cam].score();
    if (fit.fit[cam].samples < 20 || v.edge_score[cam] < config_.min_edge_score) {
      v.accepted = false;
    }
    SilhouetteMask mask;
    if (!RasterizeSilhouette(Camera(calib_, cam), object, silhouette_scratch_, &mask).ok() ||
        mask.empty()) {
      v.accepted = false;
      continue;
    }
    const ConstGrayView classes = segmentation_[cam].classes();
    uint32_t same = 0, background = 0;
    for (int y = 0; y < mask.height; ++y) {
      const uint8_t* m = mask.mask + static_cast<size_t>(y) * mask.width;
      const uint8_t* c = classes.row(mask.y0 + y) + mask.x0;
      for (int x = 0; x < mask.width; ++x) {
        if (!m[x]) continue;
        same += c[x] == colour;
        background += c[x] == kNoColourClass;
      }
    }
    const float bg_share = static_cast<float>(background) / mask.area_px;
    if (bg_share > config_.max_background_share) v.accepted = false;
    v.evidence += v.edge_score[cam] + static_cast<float>(same) / mask.area_px;
  }
  return v;
}

float ShapeRecognizer::ExplainedShare(int camera, const ColourRegion& region) const {
  const ConstGrayView explained{explained_[camera], segmentation_[camera].width(),
                                segmentation_[camera].height(), segmentation_[camera].width()};
  uint32_t n = 0;
  for (uint32_t i = region.first_run; i != kNoRun; i = segmentation_[camera].runs()[i].next) {
    const ColourRun& r = segmentation_[camera].runs()[i];
    const uint8_t* row = explained.row(r.y);
    for (int x = r.x0; x < r.x1; ++x) n += row[x] != 0;
  }
  return static_cast<float>(n) / static_cast<float>(region.area_px);
}

void ShapeRecognizer::MarkExplained(const PosedModel& object) {
  for (int cam = 0; cam < 2; ++cam) {
    SilhouetteMask mask;
    if (!RasterizeSilhouette(Camera(calib_, cam), object, silhouette_scratch_, &mask).ok()) {
      continue;
    }
    const int w = segmentation_[cam].width();
    for (int y = 0; y < mask.height; ++y) {
      const uint8_t* m = mask.mask + static_cast<size_t>(y) * mask.width;
      uint8_t* e = explained_[cam] + static_cast<size_t>(mask.y0 + y) * w + mask.x0;
      for (int x = 0; x < mask.width; ++x) e[x] |= m[x];
    }
  }
}

Status ShapeRecognizer::Process(const FrameView& left, const FrameView& right,
                                Vector<RecognizedObject>& out, ShapeStats* stats) {
  ShapeStats local;
  ShapeStats& st = stats ? *stats : local;
  st = ShapeStats{};
  if (!initialised_) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "shape recognition: Init() has not succeeded");
  }
  const FrameView frames[2] = {left, right};
  const CameraIntrinsics* intr[2] = {&calib_.left, &calib_.right};
  for (int cam = 0; cam < 2; ++cam) {
    SH_RETURN_IF_ERROR(CheckFrame(frames[cam]));
    if (frames[cam].width() != intr[cam]->width || frames[cam].height() != intr[cam]->height) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s frame is %dx%d but the calibration says %dx%d",
                           cam == 0 ? "left" : "right", frames[cam].width(), frames[cam].height(),
                           intr[cam]->width, intr[cam]->height);
    }
  }
  const int64_t t0 = now_ns_ ? now_ns_() : 0;
  for (int cam = 0; cam < 2; ++cam) {
    SH_RETURN_IF_ERROR(segmentation_[cam].Segment(frames[cam], classifier_, config_.segment));
    st.regions[cam] = static_cast<uint32_t>(segmentation_[cam].regions().size());
    st.runs_truncated |= segmentation_[cam].runs_truncated();
    st.regions_truncated |= segmentation_[cam].regions_truncated();
    std::memset(explained_[cam], 0,
                static_cast<size_t>(segmentation_[cam].width()) * segmentation_[cam].height());
    images_.rgb[cam] = segmentation_[cam].rgb();
    images_.classes[cam] = segmentation_[cam].classes();
  }
  SH_RETURN_IF_ERROR(PairRegions(calib_, segmentation_[0].regions(), segmentation_[1].regions(),
                                 config_.pairs, pairs_, &st.pairs_truncated));
  st.pairs = static_cast<uint32_t>(pairs_.size());
  st.time.segment_ms = MsSince(t0);

  n_occluders_ = 0;
  int64_t search_ns = 0, refine_ns = 0, verify_ns = 0;
  auto now = [&]() { return now_ns_ ? now_ns_() : 0; };
  for (const RegionPair& pair : pairs_) {
    const ColourRegion& rl = segmentation_[0].regions()[pair.left];
    const ColourRegion& rr = segmentation_[1].regions()[pair.right];
    if (ExplainedShare(0, rl) >= config_.explained_share ||
        ExplainedShare(1, rr) >= config_.explained_share) {
      continue;
    }
    int64_t t = now();
    Vector<Candidate, kMaxShapeCandidates> candidates;
    Candidates(pair, candidates);
    search_ns += now() - t;

    // Coarse stage: every candidate, ranked by the share of its edges found in both images.
    struct Coarse {
      PosedModel object;
      float found = 0;
    };
    Coarse coarse[kMaxShapeCandidates];
    size_t n_coarse = 0;
    t = now();
    for (const Candidate& c : candidates) {
      PosedModel object{&views_.model(c.model), {c.cam_R_model, pair.centroid_mm}};
      InitialPose(pair, &object);
      ShapeRefineResult fit;
      ++st.hypotheses;
      if (!refiner_
               .Refine(calib_, images_, classifier_, rl.colour, &object, occluders_, n_occluders_,
                       config_.coarse, &fit)
               .ok()) {
        continue;
      }
      const int samples = fit.fit[0].samples + fit.fit[1].samples;
      coarse[n_coarse++] = {
          object,
          samples ? static_cast<float>(fit.fit[0].found + fit.fit[1].found) / samples : 0.0f};
    }
    std::sort(coarse, coarse + n_coarse,
              [](const Coarse& a, const Coarse& b) { return a.found > b.found; });
    refine_ns += now() - t;
    // Fine stage and verification of the best.
    PosedModel best{nullptr, {}};
    Verdict best_verdict;
    for (size_t i = 0; i < n_coarse && i < static_cast<size_t>(config_.fine_hypotheses); ++i) {
      PosedModel object = coarse[i].object;
      t = now();
      ShapeRefineResult fit;
      const Status s = refiner_.Refine(calib_, images_, classifier_, rl.colour, &object, occluders_,
                                       n_occluders_, config_.refine, &fit);
      refine_ns += now() - t;
      if (!s.ok()) continue;
      t = now();
      const Verdict v = Evaluate(object, rl.colour, fit);
      verify_ns += now() - t;
      if (!v.accepted) continue;
      ++st.verified;
      if (best.model == nullptr || v.evidence > best_verdict.evidence) {
        best = object;
        best_verdict = v;
      }
    }
    if (best.model == nullptr) continue;
    RecognizedObject o;
    o.model = static_cast<uint16_t>(model_id_offset_ + (best.model - &views_.model(0)));
    o.cam_T_model = best.cam_T_model;
    o.verify_score[0] = best_verdict.edge_score[0];
    o.verify_score[1] = best_verdict.edge_score[1];
    o.verify_evidence = best_verdict.evidence;
    o.vote = best_verdict.evidence * 0.25f;  // evidence is a sum of four shares
    if (!out.push_back(o)) {
      st.objects_full = true;
      break;
    }
    if (n_occluders_ < kMaxOccluders) occluders_[n_occluders_++] = best;
    MarkExplained(best);
  }
  st.time.search_ms = static_cast<float>(search_ns) * 1e-6f;
  st.time.refine_ms = static_cast<float>(refine_ns) * 1e-6f;
  st.time.verify_ms = static_cast<float>(verify_ns) * 1e-6f;
  st.time.total_ms = MsSince(t0);
  return Status::Ok();
}

}  // namespace sh
