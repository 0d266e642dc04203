#include "recog/shape/shape_recognizer.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "recog/camera/calibration_check.hpp"
#include "recog/shape/sampled_row_sad.hpp"
#include "recog/shape/silhouette_placement.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {
namespace {

// Coarse hypotheses of a seed: each candidate from the centroids, and placed in a merger.
constexpr size_t kMaxCoarse = 2 * kMaxShapeCandidates;

constexpr size_t kNearestPerImage = 32;  // raw nearest views before size check and diversity
// Two coarse results this close (modulo the model's symmetries) are one start for the fine stage.
constexpr float kSameStartMm = 1.0f, kSameStartDeg = 1.0f;

ViewCamera Camera(const StereoCalibration& calib, int i) {
  return i == 0 ? LeftView(calib) : RightView(calib);
}

bool SameStart(const PosedModel& a, const PosedModel& b) {
  if (a.model != b.model || (a.cam_T_model.t_mm - b.cam_T_model.t_mm).norm() > kSameStartMm) {
    return false;
  }
  const Eigen::Matrix3f a_R_b = a.cam_T_model.R.transpose() * b.cam_T_model.R;
  for (int k = 0; k < std::max<int>(1, a.model->n_symmetries); ++k) {
    const Eigen::Matrix3f s =
        a.model->n_symmetries ? a.model->symmetry(k) : Eigen::Matrix3f::Identity();
    if (RotationAngleDeg(a_R_b * s) <= kSameStartDeg) return true;
  }
  return false;
}

}  // namespace

ShapeRefineConfig CoarseRefine() {
  ShapeRefineConfig c;
  c.sample_step_px = 6.0f;
  c.iterations = 4;
  c.search_start_px = 12.0f;
  c.search_end_px = 6.0f;
  c.visibility_every = 4;
  c.final_fit = false;
  return c;
}

ShapeRefineConfig FineRefine() {
  ShapeRefineConfig c;
  c.iterations = 8;
  c.search_start_px = 6.0f;
  c.search_end_px = 3.0f;
  c.min_start_share = 0.25f;
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
                  c.corrective_converged_mm >= 0 && c.min_edge_score >= 0 &&
                  c.min_edge_score <= 1 && c.max_background_share >= 0 &&
                  c.max_background_share <= 1 && c.explained_share > 0 && c.explained_share <= 1 &&
                  c.rounds >= 1 && c.rounds <= kShapeRounds && c.merger_area_ratio >= 0 &&
                  c.merger_area_ratio <= 1 && c.weak_edge_score >= 0 && c.weak_edge_score <= 1 &&
                  c.restart_deg >= 0 && c.restart_deg <= 90 && c.second_pass_starts >= 0 &&
                  static_cast<size_t>(c.second_pass_starts) <= kMaxShapeCandidates &&
                  c.second_pass_min_score >= 0 && c.second_pass_min_score <= 1;
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
  for (uint32_t m = 0; m < views.model_count(); ++m) near_[m] = FindNearSymmetries(views.model(m));
  calib_ = calib;
  views_ = views;
  config_ = config;
  model_id_offset_ = model_id_offset;
  now_ns_ = now_ns;
  initialised_ = true;
  return Status::Ok();
}

void ShapeRecognizer::SetParallel(const ParallelFor& parallel, int threads) {
  parallel_ = {};
  threads_ = 1;
  if (!parallel.concurrent() || threads < 2) return;
  parallel_ = parallel;
  threads_ = std::min(threads, kMaxShapeThreads);
}

template <typename Fn>
void ShapeRecognizer::Spread(int n, Fn&& fn) const {
  // Each slot takes the next k not yet taken, so a thread that ends early (a candidate given up
  // at its first pass, a worker woken late) takes over the rest instead of waiting for a fixed
  // share. Which slot takes which k varies; every k writes its own output and a slot's scratch
  // is written before it is read, so the results do not.
  const int slots = std::max(1, std::min(threads_, n));
  struct Context {
    Fn* fn = nullptr;
    int n = 0;
    std::atomic<int> next{0};
  } context{&fn, n};
  auto run_slot = [](void* c, int slot) {
    auto* ctx = static_cast<Context*>(c);
    for (int k = ctx->next.fetch_add(1); k < ctx->n; k = ctx->next.fetch_add(1)) {
      (*ctx->fn)(slot, k);
    }
  };
  if (slots == 1) {
    run_slot(&context, 0);
  } else {
    parallel_(slots, run_slot, &context);
  }
}

void ShapeRecognizer::AddStageTimes(int64_t wall_ns, const StageNs& sum) {
  // One thread: the sums are the stage times. Several: the stage's wall-clock time, shared in
  // the proportions of the threads' time.
  const int64_t busy = sum.refine + sum.verify;
  const int64_t verify =
      busy > 0 ? static_cast<int64_t>(static_cast<double>(wall_ns) *
                                      static_cast<double>(sum.verify) / static_cast<double>(busy))
               : 0;
  refine_ns_ += wall_ns - verify;
  verify_ns_ += verify;
}

float ShapeRecognizer::MsSince(int64_t start) const {
  // Nanoseconds to milliseconds.
  return now_ns_ ? static_cast<float>(now_ns_() - start) * 1e-6f : 0.0f;
}

void ShapeRecognizer::ResetBlobs() {
  for (int cam = 0; cam < 2; ++cam) {
    blobs_[cam].clear();
    std::memset(blob_ids_[cam], 0,
                static_cast<size_t>(segmentation_[cam].width()) * segmentation_[cam].height());
  }
}

bool ShapeRecognizer::AddBlob(int camera, const ColourRegion& blob, uint8_t round,
                              const uint8_t* mask, int mask_stride) {
  if (blobs_[camera].full()) return false;
  const size_t index = blobs_[camera].size();
  (void)blobs_[camera].push_back(blob);
  blob_round_[camera][index] = round;
  blob_depth_[camera][index] = 0.0f;
  const uint8_t id = static_cast<uint8_t>(index + 1);
  const int w = segmentation_[camera].width();
  for (int y = 0; y < blob.height(); ++y) {
    const uint8_t* m = mask + static_cast<ptrdiff_t>(y) * mask_stride;
    uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(blob.y0 + y) * w + blob.x0;
    for (int x = 0; x < blob.width(); ++x) {
      if (m[x]) ids[x] = id;
    }
  }
  return true;
}

bool ShapeRecognizer::BlobWindow(int camera, const ColourRegion& blob, ThreadScratch& scratch,
                                 ShapeWindow* window) const {
  // The blob's mask in the slot's silhouette raster, free while the candidates are sought.
  uint8_t* const mask_px = scratch.silhouette.mask;
  const uint8_t id = static_cast<uint8_t>(&blob - blobs_[camera].data() + 1);
  const int w = segmentation_[camera].width();
  for (int y = 0; y < blob.height(); ++y) {
    const uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(blob.y0 + y) * w + blob.x0;
    uint8_t* m = mask_px + static_cast<size_t>(y) * blob.width();
    for (int x = 0; x < blob.width(); ++x) m[x] = ids[x] == id ? 255 : 0;
  }
  const ConstGrayView mask{mask_px, blob.width(), blob.height(), blob.width()};
  return ComputeShapeWindow(mask, scratch.window, window).ok();
}

void ShapeRecognizer::Candidates(const Seed& seed, Vector<Candidate>& out) {
  out.clear();
  const int first = seed.blob[0] >= 0 ? 0 : 1;
  const uint8_t colour = blobs_[first][seed.blob[first]].colour;
  // The window of each image, its projection and then the nearest views of each image and model
  // of the colour on the worker threads (the windows, projections and searches only read; each
  // writes its own window, coefficients or list), then the candidates from the lists in image
  // and model order.
  ShapeCoefficients coefficients[2];
  bool windowed[2] = {false, false};
  int with_blob[2];  // the images the seed has a blob in
  int n_with_blob = 0;
  for (int cam = 0; cam < 2; ++cam) {
    if (seed.blob[cam] >= 0) with_blob[n_with_blob++] = cam;
  }
  Spread(n_with_blob, [&](int slot, int k) {
    const int cam = with_blob[k];
    windowed[cam] = BlobWindow(cam, blobs_[cam][seed.blob[cam]], scratch_[slot], &windows_[cam]);
  });
  int projected[2];  // the windowed images
  int n_projected = 0;
  for (int cam = 0; cam < 2; ++cam) {
    if (windowed[cam]) projected[n_projected++] = cam;
  }
  // The projection (half of the candidates' time on one thread) in a share per thread and
  // image: a mono seed's too is spread.
  const int shares = threads_;
  Spread(n_projected * shares, [&](int /*slot*/, int k) {
    const int cam = projected[k / shares];
    ProjectWindowShare(views_, windows_[cam], k % shares, shares, &coefficients[cam]);
  });
  struct Search {
    int camera = 0;
    uint32_t model = 0;
    Vector<ViewMatch, kNearestPerImage> nearest;
  };
  Search searches[2 * kMaxShapeModels];
  int n_searches = 0;
  for (int cam = 0; cam < 2; ++cam) {
    for (uint32_t m = 0; m < views_.model_count() && windowed[cam]; ++m) {
      if (colour_of_model_[m] != colour) continue;
      searches[n_searches].camera = cam;
      searches[n_searches++].model = m;
    }
  }
  // The nearest views of each model of the colour on its own: models with many views (no
  // symmetry) would otherwise crowd out the others. The threads take the searches with the most
  // views first (a search's time grows with its views), so that no long one is left to the end.
  // (An insertion sort: stable, and no buffer from the heap as std::stable_sort takes.)
  int order[2 * kMaxShapeModels];
  const auto n_views = [&](int k) { return views_.shape_model(searches[k].model).n_views; };
  for (int k = 0; k < n_searches; ++k) {
    int j = k;
    for (; j > 0 && n_views(order[j - 1]) < n_views(k); --j) order[j] = order[j - 1];
    order[j] = k;
  }
  Spread(n_searches, [&](int /*slot*/, int j) {
    Search& search = searches[order[j]];
    NearestViews(views_, coefficients[search.camera], 1u << search.model, kNearestPerImage,
                 search.nearest);
  });
  for (int k = 0; k < n_searches; ++k) {
    const int cam = searches[k].camera;
    const ColourRegion& blob = blobs_[cam][seed.blob[cam]];
    const ViewCamera view = Camera(calib_, cam);
    const CameraIntrinsics& ci = view.intrinsics;
    // The part's centre in this camera: triangulated, or on the blob's viewing ray (its depth
    // does not matter for the ray frame).
    Eigen::Vector3f centre;
    if (seed.stereo) {
      centre = view.cam_T_left * seed.centroid_mm;
    } else {
      const Eigen::Vector2d xy = UndistortPixel(ci, {blob.cx, blob.cy});
      centre = Eigen::Vector3f(static_cast<float>(xy.x()), static_cast<float>(xy.y()), 1.0f);
    }
    // A blob cut by the image border is smaller than its part; without a triangulated depth
    // there is no size to compare: no size check then.
    const bool clipped =
        blob.x0 == 0 || blob.y0 == 0 || blob.x1 == ci.width - 1 || blob.y1 == ci.height - 1;
    // Box size in pixels -> millimetres at the part's depth.
    const float extent[2] = {static_cast<float>(blob.width()) * centre.z() / float(ci.fx),
                             static_cast<float>(blob.height()) * centre.z() / float(ci.fy)};
    const Eigen::Matrix3f left_R_ray = view.cam_T_left.R.transpose() * RayFrame(centre);
    const size_t first_of_model = out.size();
    int taken = 0;
    for (const ViewMatch& match : searches[k].nearest) {
      if (taken == config_.views_per_image) break;
      const ShapeViewRecord& rec = views_.view(match.view);
      if (seed.stereo && !clipped) {
        bool fits = true;
        for (int e_k = 0; e_k < 2; ++e_k) {
          const float e = UQExtentMm::FromRaw(rec.extent_mm[e_k]).ToFloat();
          fits &= e <= config_.max_extent_ratio * extent[e_k] &&
                  extent[e_k] <= config_.max_extent_ratio * e;
        }
        if (!fits) continue;
      }
      Candidate c{rec.model, match.view, cam, left_R_ray * views_.ViewRotation(match.view)};
      bool diverse = true;
      for (size_t i = first_of_model; i < out.size(); ++i) {
        if (RotationAngleDeg(out[i].cam_R_model.transpose() * c.cam_R_model) <
            config_.diverse_deg) {
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

bool ShapeRecognizer::InitialPoseStereo(const Seed& seed, bool place, SilhouetteScratch& scratch,
                                        PosedModel* object) const {
  // Orientation relative to the viewing ray stays as the view gave it while the position moves.
  const Eigen::Matrix3f ray_R_model =
      RayFrame(seed.centroid_mm).transpose() * object->cam_T_model.R;
  object->cam_T_model.t_mm = seed.centroid_mm;
  const ColourRegion* blobs[2] = {&blobs_[0][seed.blob[0]], &blobs_[1][seed.blob[1]]};
  bool placed = false;
  for (int it = 0; it < config_.corrective_iterations; ++it) {
    object->cam_T_model.R = RayFrame(object->cam_T_model.t_mm) * ray_R_model;
    Eigen::Vector2d target[2];
    bool ok = true;
    for (int cam = 0; cam < 2 && ok; ++cam) {
      const ViewCamera view = Camera(calib_, cam);
      SilhouetteMask mask;
      Eigen::Vector2d origin;
      ok = RasterizeSilhouette(view, *object, scratch, &mask).ok() && !mask.empty() &&
           ProjectToPixel(view.intrinsics,
                          (view.cam_T_left * object->cam_T_model.t_mm).cast<double>(), &origin);
      if (!ok) break;
      const ColourRegion& blob = *blobs[cam];
      Eigen::Vector2d shift;
      if (place && PlaceInMerger(cam, seed.blob[cam], mask, &shift)) {
        target[cam] = origin + shift;
        placed = true;
        continue;
      }
      // Where the origin must project for the predicted centroid to meet the observed one.
      target[cam] = origin + Eigen::Vector2d(blob.cx - mask.cx, blob.cy - mask.cy);
    }
    RayMidpoint mid;
    if (!ok || !TriangulatePixels(calib_, target[0], target[1], &mid) || !(mid.depth_a_mm > 0)) {
      break;
    }
    const float moved_mm = (mid.p_mm.cast<float>() - object->cam_T_model.t_mm).norm();
    object->cam_T_model.t_mm = mid.p_mm.cast<float>();
    if (moved_mm < config_.corrective_converged_mm) break;
  }
  object->cam_T_model.R = RayFrame(object->cam_T_model.t_mm) * ray_R_model;
  return !place || placed;
}

float ShapeRecognizer::BlobDepth(int camera, const ColourRegion& blob) const {
  constexpr float kMinDepthMm = 150.0f, kMaxDepthMm = 2500.0f;
  constexpr int kMaxSteps = 1024;
  constexpr int kSampleStride = 2;  // every other pixel of the blob in both directions
  const int other = 1 - camera;
  const ViewCamera view = Camera(calib_, camera), other_view = Camera(calib_, other);
  const CameraIntrinsics& ci = view.intrinsics;
  const CameraIntrinsics& co = other_view.intrinsics;
  const RigidTransform other_T_cam = other_view.cam_T_left * view.cam_T_left.Inverse();
  const Eigen::Vector2d xy = UndistortPixel(ci, {blob.cx, blob.cy});
  const Eigen::Vector3f ray(static_cast<float>(xy.x()), static_cast<float>(xy.y()), 1.0f);
  // Steps uniform in inverse depth (uniform in disparity), about a pixel apart.
  Eigen::Vector2d near_px, far_px;
  if (!ProjectToPixel(co, (other_T_cam * (kMinDepthMm * ray)).cast<double>(), &near_px) ||
      !ProjectToPixel(co, (other_T_cam * (kMaxDepthMm * ray)).cast<double>(), &far_px)) {
    return 0.0f;
  }
  const int steps = std::min(kMaxSteps, static_cast<int>((near_px - far_px).norm()) + 2);
  const uint8_t id = static_cast<uint8_t>(&blob - blobs_[camera].data() + 1);
  const int w = segmentation_[camera].width();
  const ImageView<const Rgb8> src = images_.rgb[camera], dst = images_.rgb[other];
  const ConstGrayView dst_classes = images_.classes[other];
  // The blob's sampled pixels: no shift maps more of them, so a sum of differences that already
  // reaches best_cost times their count cannot give a lower mean; the depth is dropped there.
  // Per sampled row, the first and last sampled columns that are the blob's: the shifts read
  // between them only (the same pixels; an empty row has last < first), in runs of the blob's
  // columns compared in byte vectors (SampleRowSad). A row whose sampled columns between them
  // are all the blob's (most rows of a compact part) is one run, found without reading its ids.
  struct Span {
    int16_t first, last;
    bool full;
  };
  Span spans[kMaxImageHeight / kSampleStride + 1];
  uint32_t n_blob = 0;
  for (int y = blob.y0, r = 0; y <= blob.y1; y += kSampleStride, ++r) {
    const uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(y) * w;
    int first = blob.x1 + 1, last = blob.x0 - 1, n_row = 0;
    for (int x = blob.x0; x <= blob.x1; x += kSampleStride) {
      if (ids[x] != id) continue;
      ++n_row;
      first = std::min(first, x);
      last = x;
    }
    n_blob += static_cast<uint32_t>(n_row);
    spans[r] = {static_cast<int16_t>(first), static_cast<int16_t>(last),
                n_row > 0 && n_row == (last - first) / kSampleStride + 1};
  }
  if (n_blob == 0) return 0.0f;
  // The depth steps in contiguous ranges the threads take in turn, with one best for all: a step
  // is dropped once its cost cannot beat the best any range has found (a cost known to be larger,
  // or equal at a later step), so the depth is the least cost's and, of equal costs, the first
  // step's, as a scan in order finds it, whichever thread finds it when. Several ranges per
  // thread, so that one with few early drops does not keep the others waiting.
  //
  // Within a range every kCoarseEvery-th step comes first, then the others: a cost near the
  // least found early drops most of the remaining steps after a few rows.
  constexpr int kCoarseEvery = 8;
  constexpr int kRangesPerThread = 4;
  // (cost, step) as one number ordered as the pairs are (a non-negative float's bits grow with
  // it): the best is the least.
  const auto pack = [](float cost, int k) {
    uint32_t bits;
    std::memcpy(&bits, &cost, sizeof bits);
    return (static_cast<uint64_t>(bits) << 32) | static_cast<uint32_t>(k);
  };
  const auto depth_at = [&](int k) {
    const float inv = (1.0f / kMaxDepthMm) + (1.0f / kMinDepthMm - 1.0f / kMaxDepthMm) *
                                                 static_cast<float>(k) / (steps - 1);
    return 1.0f / inv;
  };
  std::atomic<uint64_t> best{pack(1e30f, std::numeric_limits<int>::max())};
  const int ranges = threads_ > 1 ? std::min(kRangesPerThread * threads_, steps) : 1;
  Spread(ranges, [&](int /*slot*/, int range) {
    const int begin = steps * range / ranges, end = steps * (range + 1) / ranges;
    auto try_step = [&](int k) {
      const float depth = depth_at(k);
      Eigen::Vector2d centre_other;
      if (!ProjectToPixel(co, (other_T_cam * (depth * ray)).cast<double>(), &centre_other)) {
        return;
      }
      // The blob moves as a whole: its centroid's correspondence gives the shift.
      const int dx = static_cast<int>(std::lround(centre_other.x() - blob.cx));
      const int dy = static_cast<int>(std::lround(centre_other.y() - blob.cy));
      uint32_t n = 0, same = 0;
      uint32_t sad = 0;
      bool beaten = false;
      for (int y = blob.y0, r = 0; y <= blob.y1 && !beaten; y += kSampleStride, ++r) {
        const uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(y) * w;
        const int yo = y + dy;
        if (yo < 0 || yo >= co.height) continue;
        const Rgb8* s_row = src.row(y);
        const Rgb8* d_row = dst.row(yo);
        const uint8_t* c_row = dst_classes.row(yo);
        // The sampled columns whose shifted pixel lies in the other image, compared in runs of
        // the blob's columns (a full row is one run).
        const int first = spans[r].first;
        const int lo = std::max(first, -dx), hi = std::min<int>(spans[r].last, co.width - 1 - dx);
        const int lo_sampled = lo + (lo - first) % kSampleStride;
        const int hi_sampled = hi - (hi - first) % kSampleStride;
        const auto add_run = [&](int x0, int x1) {  // sampled columns x0..x1, the blob's
          const int m = (x1 - x0) / kSampleStride + 1;
          const SampledRowSad run =
              SampleRowSad(s_row + x0, d_row + x0 + dx, c_row + x0 + dx, m, blob.colour);
          n += static_cast<uint32_t>(m);
          same += run.same;
          sad += run.sad;
        };
        const bool lands = hi >= first && lo_sampled <= hi_sampled;
        if (lands && spans[r].full) {
          add_run(lo_sampled, hi_sampled);
        } else if (lands) {
          for (int x = lo_sampled; x <= hi_sampled; x += kSampleStride) {
            if (ids[x] != id) continue;
            const int run_first = x;
            while (x + kSampleStride <= hi_sampled && ids[x + kSampleStride] == id) {
              x += kSampleStride;
            }
            add_run(run_first, x);
          }
        }
        const float least = static_cast<float>(sad) / static_cast<float>(n_blob);
        beaten = pack(least, k) > best.load(std::memory_order_relaxed);
      }
      // Most of the blob must land on its colour in the other image.
      if (beaten || n == 0 || same * 10 < n * 7) return;
      const uint64_t mine = pack(static_cast<float>(sad) / n, k);
      uint64_t seen = best.load(std::memory_order_relaxed);
      while (mine < seen && !best.compare_exchange_weak(seen, mine, std::memory_order_relaxed)) {
      }
    };
    for (int k = begin; k < end; k += kCoarseEvery) try_step(k);
    for (int k = begin; k < end; ++k) {
      if ((k - begin) % kCoarseEvery != 0) try_step(k);
    }
  });
  const int step = static_cast<int>(best.load() & 0xffffffffu);
  return step == std::numeric_limits<int>::max() ? 0.0f : depth_at(step);
}

bool ShapeRecognizer::InitialPoseMono(const Seed& seed, const Candidate& c, bool place,
                                      SilhouetteScratch& scratch, PosedModel* object) const {
  const int cam = c.camera;
  const ColourRegion& blob = blobs_[cam][seed.blob[cam]];
  const ViewCamera view = Camera(calib_, cam);
  const CameraIntrinsics& ci = view.intrinsics;
  // Depth: that of the blob's surface (matched in the other image) plus half the model's radius;
  // else, when nothing matched there (the pixels land on another part in the other image, as a
  // part split from a region of two shows), that of the stereo pair the blob (or the blob it came
  // from) was triangulated in; else from size, the view's box (mm at the origin's depth) against
  // the blob's (px).
  const ShapeViewRecord& rec = views_.view(c.view);
  const float extent_mm = UQExtentMm::FromRaw(rec.extent_mm[0]).ToFloat() +
                          UQExtentMm::FromRaw(rec.extent_mm[1]).ToFloat();
  const float extent_px = static_cast<float>(blob.width() + blob.height());
  // The blob's surface lies in front of the model's origin: half its radius, on average.
  const float known_depth = seed.surface_mm > 0
                                ? seed.surface_mm + 0.5f * views_.shape_model(c.model).radius_mm
                                : seed.pair_depth_mm;
  float depth = known_depth > 0 ? known_depth : static_cast<float>(ci.fx) * extent_mm / extent_px;
  const Eigen::Matrix3f cam_R_left = view.cam_T_left.R;
  // ray_R_model in this camera's ray frame at the blob's centroid.
  Eigen::Vector2d xy = UndistortPixel(ci, {blob.cx, blob.cy});
  const Eigen::Vector3f ray0(static_cast<float>(xy.x()), static_cast<float>(xy.y()), 1.0f);
  const Eigen::Matrix3f ray_R_model = RayFrame(ray0).transpose() * cam_R_left * c.cam_R_model;
  const RigidTransform left_T_cam = view.cam_T_left.Inverse();
  Eigen::Vector2d target(blob.cx, blob.cy);
  bool placed = false;
  Eigen::Vector3f previous_t_cam = Eigen::Vector3f::Zero();
  for (int it = 0; it <= config_.corrective_iterations; ++it) {
    xy = UndistortPixel(ci, target);
    const Eigen::Vector3f t_cam =
        depth * Eigen::Vector3f(static_cast<float>(xy.x()), static_cast<float>(xy.y()), 1.0f);
    RigidTransform cam_T_model{RayFrame(t_cam) * ray_R_model, t_cam};
    object->cam_T_model = left_T_cam * cam_T_model;
    if (it == config_.corrective_iterations ||
        (it > 0 && (t_cam - previous_t_cam).norm() < config_.corrective_converged_mm)) {
      break;
    }
    previous_t_cam = t_cam;
    SilhouetteMask mask;
    Eigen::Vector2d origin;
    if (!RasterizeSilhouette(view, *object, scratch, &mask).ok() || mask.empty() ||
        !ProjectToPixel(ci, t_cam.cast<double>(), &origin)) {
      return false;
    }
    // Centroid offset as in the stereo case; the box's size corrects the depth.
    // The box of the inside pixels: each row read from both ends to its first inside pixel.
    int x0 = mask.width, x1 = -1, y0 = mask.height, y1 = -1;
    for (int y = 0; y < mask.height; ++y) {
      const uint8_t* row = mask.mask + static_cast<size_t>(y) * mask.width;
      int first = 0, last = mask.width - 1;
      while (first < mask.width && !row[first]) ++first;
      if (first == mask.width) continue;
      while (!row[last]) --last;
      x0 = std::min(x0, first), x1 = std::max(x1, last), y0 = std::min(y0, y), y1 = y;
    }
    if (x1 < x0) return false;
    if (known_depth <= 0) depth *= static_cast<float>(x1 - x0 + 1 + y1 - y0 + 1) / extent_px;
    Eigen::Vector2d shift;
    if (place && PlaceInMerger(cam, seed.blob[cam], mask, &shift)) {
      target = origin + shift;
      placed = true;
    } else {
      target = origin + Eigen::Vector2d(blob.cx - mask.cx, blob.cy - mask.cy);
    }
  }
  return !place || placed;
}

bool ShapeRecognizer::PlaceInMerger(int camera, int blob_index, const SilhouetteMask& silhouette,
                                    Eigen::Vector2d* shift) const {
  // A blob much larger than the predicted silhouette merges this part with another of its
  // colour (one region). Pixels of accepted parts count as fitting (the part may lie behind
  // them); half the silhouette at least must fit at the best shift (a blob of an earlier round
  // whose pixels later blobs took has no say).
  constexpr float kMinOverlap = 0.5f;
  const ColourRegion& blob = blobs_[camera][static_cast<size_t>(blob_index)];
  if (!(static_cast<float>(silhouette.area_px) <
        config_.merger_area_ratio * static_cast<float>(blob.area_px))) {
    return false;
  }
  const int w = segmentation_[camera].width(), h = segmentation_[camera].height();
  const ConstGrayView hidden{explained_[camera], w, h, w};
  Placement placed;
  if (!PlaceSilhouette(silhouette, BlobIds(camera), static_cast<uint8_t>(blob_index + 1), hidden,
                       {blob.x0, blob.y0, blob.x1, blob.y1}, &placed) ||
      placed.overlap < kMinOverlap) {
    return false;
  }
  *shift = Eigen::Vector2d(placed.dx, placed.dy);
  return true;
}

bool ShapeRecognizer::TrySeed(const Seed& seed, Vector<RecognizedObject>& out, ShapeStats& st) {
  const int first = seed.blob[0] >= 0 ? 0 : 1;
  const uint8_t colour = blobs_[first][seed.blob[first]].colour;
  int64_t t = Now();
  Vector<Candidate, kMaxShapeCandidates> candidates;
  Candidates(seed, candidates);
  search_ns_ += Now() - t;

  // Coarse stage: every candidate, ranked by the share of its edges found in both images.
  struct Coarse {
    PosedModel object;
    float found = 0;
    bool posed = false, refined = false;
  };
  // Each candidate from the blobs' centroids; for a seed none of whose first starts verified,
  // where a blob merges the part with another of its colour, each candidate again from where
  // its silhouette fits the blob best (PlaceInMerger). Each run appends its refined results,
  // ranked among themselves, and returns where they start.
  Coarse coarse[kMaxCoarse];
  size_t n_coarse = 0;
  const int n_candidates = static_cast<int>(candidates.size());
  const auto run_coarse = [&](bool place) {
    const size_t first = n_coarse;
    Coarse* jobs = coarse + first;
    const int64_t t_run = Now();
    Spread(n_candidates, [&](int slot, int k) {
      const Candidate& c = candidates[static_cast<size_t>(k)];
      Coarse& r = jobs[k];
      r = Coarse{};
      r.object = {&views_.model(c.model), {c.cam_R_model, seed.centroid_mm}};
      SilhouetteScratch& silhouette = scratch_[slot].silhouette;
      r.posed = seed.stereo ? InitialPoseStereo(seed, place, silhouette, &r.object)
                            : InitialPoseMono(seed, c, place, silhouette, &r.object);
      if (!r.posed) return;
      ShapeRefineResult fit;
      r.refined = scratch_[slot]
                      .refiner
                      .Refine(calib_, images_, colour, &r.object, occluders_, n_occluders_,
                              config_.coarse, &fit)
                      .ok();
      const int samples = fit.fit[0].samples + fit.fit[1].samples;
      r.found = samples ? static_cast<float>(fit.fit[0].found + fit.fit[1].found) / samples : 0.0f;
    });
    // In candidate order, as one thread would have left them.
    for (int k = 0; k < n_candidates; ++k) {
      st.hypotheses += jobs[k].posed;
      if (jobs[k].refined) coarse[n_coarse++] = jobs[k];
    }
    std::sort(coarse + first, coarse + n_coarse,
              [](const Coarse& a, const Coarse& b) { return a.found > b.found; });
    refine_ns_ += Now() - t_run;
    return first;
  };
  run_coarse(false);
  // Fine stage and verification of the best. Two views that the coarse stage took to one pose:
  // the fine stage would repeat itself (compared with the starts it does refine, not with those
  // it skips), so the starts are chosen before any is refined.
  PosedModel starts[kMaxCoarse];
  bool chosen[kMaxCoarse] = {};
  size_t n_starts = 0;
  const auto choose = [&](size_t limit, size_t from) {
    const size_t first_new = n_starts;
    for (size_t i = from; i < n_coarse && n_starts - first_new < limit; ++i) {
      if (chosen[i]) continue;
      chosen[i] = true;
      bool repeat = false;
      for (size_t j = 0; j < n_starts && !repeat; ++j) {
        repeat = SameStart(starts[j], coarse[i].object);
      }
      if (!repeat) starts[n_starts++] = coarse[i].object;
    }
    return n_starts - first_new;
  };
  choose(static_cast<size_t>(config_.fine_hypotheses), 0);
  PosedModel best{nullptr, {}};
  Verdict best_verdict;
  PosedModel weak{nullptr, {}};  // the unverified fine result with the most edges confirmed
  Verdict weak_verdict;
  RefineStarts(colour, starts, n_starts, &best, &best_verdict, &weak, &weak_verdict, st);
  // A blob that merges two parts of one colour: its centroid lies between them.
  if (best.model == nullptr && config_.merger_area_ratio > 0) {
    const size_t placed = run_coarse(true);
    if (n_coarse > placed) {
      ++st.merger_seeds;
      const size_t first = n_starts;
      const size_t added = choose(static_cast<size_t>(config_.fine_hypotheses), placed);
      RefineStarts(colour, starts + first, added, &best, &best_verdict, &weak, &weak_verdict, st);
      st.merger_found += best.model != nullptr;
    }
  }
  // Second, wider pass for a seed none of whose first starts verified: the coarse results not
  // refined yet, then the unverified result nearest to verifying from turned starts.
  if (best.model == nullptr && config_.second_pass) {
    const size_t first = n_starts;
    const size_t added = choose(static_cast<size_t>(config_.second_pass_starts), 0);
    RefineStarts(colour, starts + first, added, &best, &best_verdict, &weak, &weak_verdict, st);
    // A part with a near symmetry (the bracket) whose every start settled half a turn from the
    // truth confirms too few edges there to verify: the weak result's turned poses are refined
    // too before it is restarted.
    if (best.model == nullptr && weak.model != nullptr && config_.near_symmetries) {
      PosedModel turned[kMaxNearSymmetries];
      const int n_turned = TurnedPoses(weak, turned);
      RefineStarts(colour, turned, static_cast<size_t>(n_turned), &best, &best_verdict, &weak,
                   &weak_verdict, st);
      st.weak_turned += n_turned > 0;
      st.weak_turned_kept += best.model != nullptr;
    }
    if (best.model == nullptr && weak.model != nullptr) {
      best = weak;
      best_verdict = weak_verdict;
      RestartWeak(colour, &best, &best_verdict, st);
      if (!best_verdict.accepted) best.model = nullptr;
    }
  }
  if (best.model == nullptr) return false;
  // A part with a near symmetry (the bracket) may have settled half a turn from the truth: the
  // turned pose, refined the same way, replaces it when the images explain it better.
  PosedModel turned_poses[kMaxNearSymmetries];
  const int n_turned = config_.near_symmetries ? TurnedPoses(best, turned_poses) : 0;
  for (int k = 0; k < n_turned; ++k) {
    PosedModel& turned = turned_poses[k];
    Verdict v;
    StageNs ns;
    const bool refined = RefineAndEvaluate(colour, scratch_[0], &turned, &v, &ns);
    AddStageTimes(ns.refine + ns.verify, ns);
    if (!refined) continue;
    ++st.turned;
    if (v.accepted && v.evidence > best_verdict.evidence) {
      best = turned;
      best_verdict = v;
      ++st.turned_kept;
    }
  }
  RestartWeak(colour, &best, &best_verdict, st);
  RecognizedObject o;
  o.model = static_cast<uint16_t>(model_id_offset_ + (best.model - &views_.model(0)));
  o.cam_T_model = best.cam_T_model;
  o.verify_score[0] = best_verdict.edge_score[0];
  o.verify_score[1] = best_verdict.edge_score[1];
  o.verify_evidence = best_verdict.evidence;
  o.vote = best_verdict.evidence * 0.25f;  // evidence is a sum of four shares
  if (!out.push_back(o)) {
    st.objects_full = true;
    return false;
  }
  if (n_occluders_ < kMaxOccluders) occluders_[n_occluders_++] = best;
  MarkExplained(best);
  return true;
}

int ShapeRecognizer::TurnedPoses(const PosedModel& found, PosedModel* turned) const {
  const NearSymmetries& near = near_[found.model - &views_.model(0)];
  for (int k = 0; k < near.n; ++k) {
    turned[k] = found;
    // x -> R (S x + s) + t: rotation R S, translation t + R s.
    turned[k].cam_T_model.R = found.cam_T_model.R * near.R[k];
    turned[k].cam_T_model.t_mm = found.cam_T_model.t_mm + found.cam_T_model.R * near.t_mm[k];
  }
  return near.n;
}

void ShapeRecognizer::RefineStarts(uint8_t colour, const PosedModel* starts, size_t n,
                                   PosedModel* best, Verdict* best_verdict, PosedModel* weak,
                                   Verdict* weak_verdict, ShapeStats& st) {
  struct Fine {
    PosedModel object;
    Verdict verdict;
    bool refined = false;
    StageNs ns;
  };
  Fine fine[kMaxShapeCandidates];
  const int64_t t = Now();
  Spread(static_cast<int>(n), [&](int slot, int k) {
    Fine& f = fine[k];
    f.object = starts[k];
    f.refined = RefineAndEvaluate(colour, scratch_[slot], &f.object, &f.verdict, &f.ns);
  });
  StageNs sum;
  for (size_t k = 0; k < n; ++k) {
    const Fine& f = fine[k];
    sum.refine += f.ns.refine;
    sum.verify += f.ns.verify;
    if (!f.refined) continue;
    if (!f.verdict.accepted) {
      const float edges = std::min(f.verdict.edge_score[0], f.verdict.edge_score[1]);
      if (edges >= config_.second_pass_min_score &&
          (weak->model == nullptr ||
           edges > std::min(weak_verdict->edge_score[0], weak_verdict->edge_score[1]))) {
        *weak = f.object;
        *weak_verdict = f.verdict;
      }
      continue;
    }
    ++st.verified;
    if (best->model == nullptr || f.verdict.evidence > best_verdict->evidence) {
      *best = f.object;
      *best_verdict = f.verdict;
    }
  }
  AddStageTimes(Now() - t, sum);
}

void ShapeRecognizer::RestartWeak(uint8_t colour, PosedModel* best, Verdict* verdict,
                                  ShapeStats& st) {
  if (config_.restart_deg <= 0 ||
      std::min(verdict->edge_score[0], verdict->edge_score[1]) >= config_.weak_edge_score) {
    return;
  }
  ++st.restarted;
  constexpr int kStarts = 6;  // +- about each model axis
  const float angle_rad = config_.restart_deg * 3.14159265f / 180.0f;
  PosedModel starts[kStarts];
  for (int k = 0; k < kStarts; ++k) {
    const float sign = (k & 1) ? -1.0f : 1.0f;
    starts[k] = *best;
    starts[k].cam_T_model.R =
        best->cam_T_model.R *
        Eigen::AngleAxisf(sign * angle_rad, Eigen::Vector3f::Unit(k / 2)).toRotationMatrix();
  }
  PosedModel found{nullptr, {}}, unverified{nullptr, {}};
  Verdict found_verdict, unverified_verdict;
  RefineStarts(colour, starts, kStarts, &found, &found_verdict, &unverified, &unverified_verdict,
               st);
  const bool kept =
      found.model != nullptr && (!verdict->accepted || found_verdict.evidence > verdict->evidence);
  if (kept) {
    *best = found;
    *verdict = found_verdict;
  }
  st.restart_kept += kept;
}

bool ShapeRecognizer::RefineAndEvaluate(uint8_t colour, ThreadScratch& scratch, PosedModel* object,
                                        Verdict* verdict, StageNs* ns) const {
  int64_t t = Now();
  ShapeRefineResult fit;
  const Status s = scratch.refiner.Refine(calib_, images_, colour, object, occluders_, n_occluders_,
                                          config_.refine, &fit);
  ns->refine = Now() - t;
  if (!s.ok()) return false;
  t = Now();
  *verdict = Evaluate(*object, colour, fit, scratch.silhouette);
  ns->verify = Now() - t;
  return true;
}

ShapeRecognizer::Verdict ShapeRecognizer::Evaluate(const PosedModel& object, uint8_t colour,
                                                   const ShapeRefineResult& fit,
                                                   SilhouetteScratch& scratch) const {
  Verdict v;
  v.accepted = true;
  for (int cam = 0; cam < 2; ++cam) {
    v.edge_score[cam] = fit.fit[cam].score();
    if (fit.fit[cam].samples < 20 || v.edge_score[cam] < config_.min_edge_score) {
      v.accepted = false;
    }
    SilhouetteMask mask;
    if (!RasterizeSilhouette(Camera(calib_, cam), object, scratch, &mask).ok() || mask.empty()) {
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
    v.background_share[cam] = bg_share;
    if (bg_share > config_.max_background_share) v.accepted = false;
    v.evidence += v.edge_score[cam] + static_cast<float>(same) / mask.area_px;
  }
  return v;
}

Status ShapeRecognizer::Assess(PosedModel* object, const PosedModel* occluders, size_t n_occluders,
                               Assessment* out) const {
  *out = Assessment{};
  if (!initialised_ || object == nullptr || object->model == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "shape assessment: no frame or model");
  }
  const int m = static_cast<int>(object->model - &views_.model(0));
  if (m < 0 || m >= static_cast<int>(views_.model_count())) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "shape assessment: the model is not the view database's");
  }
  const uint8_t colour = colour_of_model_[m];
  ShapeRefineResult fit;
  // From the truth the refinement runs to its end, however few edges it finds at the start.
  ShapeRefineConfig refine = config_.refine;
  refine.min_start_share = 0.0f;
  const Status s = scratch_[0].refiner.Refine(calib_, images_, colour, object, occluders,
                                              n_occluders, refine, &fit);
  if (!s.ok()) return Status::Ok();
  out->refined = true;
  const Verdict v = Evaluate(*object, colour, fit, scratch_[0].silhouette);
  out->accepted = v.accepted;
  for (int cam = 0; cam < 2; ++cam) {
    out->edge_score[cam] = v.edge_score[cam];
    out->background_share[cam] = v.background_share[cam];
  }
  return Status::Ok();
}

float ShapeRecognizer::ExplainedShare(int camera, const ColourRegion& blob) const {
  const uint8_t id = static_cast<uint8_t>(&blob - blobs_[camera].data() + 1);
  const int w = segmentation_[camera].width();
  uint32_t n = 0;
  for (int y = blob.y0; y <= blob.y1; ++y) {
    const uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(y) * w;
    const uint8_t* e = explained_[camera] + static_cast<size_t>(y) * w;
    for (int x = blob.x0; x <= blob.x1; ++x) n += ids[x] == id && e[x] != 0;
  }
  return static_cast<float>(n) / static_cast<float>(blob.area_px);
}

int ShapeRecognizer::DeriveBlobs(int camera, uint8_t round, ShapeStats& st) {
  const int w = segmentation_[camera].width();
  const size_t n_before = blobs_[camera].size();
  int added = 0;
  for (size_t b = 0; b < n_before; ++b) {
    if (blob_round_[camera][b] + 1 != round) continue;
    const ColourRegion blob = blobs_[camera][b];
    const size_t box = static_cast<size_t>(blob.width()) * blob.height();
    if (box > kMaxSplitPixels) continue;  // larger than any part at a working distance
    const uint8_t id = static_cast<uint8_t>(b + 1);
    // The blob's unexplained pixels.
    uint32_t left_over = 0;
    for (int y = 0; y < blob.height(); ++y) {
      const uint8_t* ids = blob_ids_[camera] + static_cast<size_t>(blob.y0 + y) * w + blob.x0;
      const uint8_t* e = explained_[camera] + static_cast<size_t>(blob.y0 + y) * w + blob.x0;
      uint8_t* m = region_mask_ + static_cast<size_t>(y) * blob.width();
      for (int x = 0; x < blob.width(); ++x) {
        m[x] = ids[x] == id && !e[x] ? 255 : 0;
        left_over += m[x] != 0;
      }
    }
    if (left_over < static_cast<uint32_t>(config_.segment.min_area_px)) continue;
    MaskPart parts[kMaxMaskParts];
    const GrayView labels{part_labels_, blob.width(), blob.height(), blob.width()};
    const float ratio = round + 1 == config_.rounds ? config_.last_split_ratio : config_.neck_ratio;
    const Result<int> n =
        MaskParts({region_mask_, blob.width(), blob.height(), blob.width()}, true, ratio,
                  config_.segment.min_area_px, parts_scratch_, labels, parts);
    if (!n.ok()) continue;
    int n_parts = *n;
    // The whole blob again, unsplit and untouched: a part in front of another of its colour,
    // without a neck between them. The opening by a disc of a share of the blob's largest
    // inscribed radius keeps the part with the largest disc and drops the thinner rest.
    if (*n == 1 && left_over == blob.area_px) {
      const GrayView opened{part_labels_, blob.width(), blob.height(), blob.width()};
      const Result<uint32_t> kept =
          OpenMask({region_mask_, blob.width(), blob.height(), blob.width()}, config_.opening_ratio,
                   parts_scratch_, opened);
      if (!kept.ok() || *kept < static_cast<uint32_t>(config_.segment.min_area_px) ||
          *kept > 0.9f * static_cast<float>(blob.area_px)) {
        continue;
      }
      std::memcpy(region_mask_, part_labels_, box);
      const Result<int> m =
          MaskParts({region_mask_, blob.width(), blob.height(), blob.width()}, false, 0.0f,
                    config_.segment.min_area_px, parts_scratch_, labels, parts);
      if (!m.ok() || *m == 0) continue;
      n_parts = *m;
    }
    for (int k = 0; k < n_parts; ++k) {
      ColourRegion part;
      part.colour = blob.colour;
      part.area_px = parts[k].area_px;
      part.x0 = blob.x0 + parts[k].x0;
      part.y0 = blob.y0 + parts[k].y0;
      part.x1 = blob.x0 + parts[k].x1;
      part.y1 = blob.y0 + parts[k].y1;
      part.cx = static_cast<float>(blob.x0) + parts[k].cx;
      part.cy = static_cast<float>(blob.y0) + parts[k].cy;
      // The part's own mask: its label within its box.
      for (int y = 0; y < part.height(); ++y) {
        const uint8_t* l =
            part_labels_ + static_cast<size_t>(parts[k].y0 + y) * blob.width() + parts[k].x0;
        uint8_t* m = region_mask_ + static_cast<size_t>(y) * part.width();
        for (int x = 0; x < part.width(); ++x) m[x] = l[x] == parts[k].label ? 255 : 0;
      }
      if (!AddBlob(camera, part, round, region_mask_, part.width())) {
        st.blobs_full = true;
        return added;
      }
      blob_depth_[camera][blobs_[camera].size() - 1] = blob_depth_[camera][b];
      ++added;
    }
  }
  return added;
}

void ShapeRecognizer::MarkExplained(const PosedModel& object) {
  for (int cam = 0; cam < 2; ++cam) {
    SilhouetteMask mask;
    if (!RasterizeSilhouette(Camera(calib_, cam), object, scratch_[0].silhouette, &mask).ok()) {
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
  const int64_t t0 = Now();
  search_ns_ = refine_ns_ = verify_ns_ = 0;
  // Both images segmented at once (each into its own segmentation; the classifier only reads).
  Status segmented[2];
  Spread(2, [&](int /*slot*/, int cam) {
    segmented[cam] = segmentation_[cam].Segment(frames[cam], classifier_, config_.segment);
  });
  for (int cam = 0; cam < 2; ++cam) {
    SH_RETURN_IF_ERROR(segmented[cam]);
    st.regions[cam] = static_cast<uint32_t>(segmentation_[cam].regions().size());
    st.runs_truncated |= segmentation_[cam].runs_truncated();
    st.regions_truncated |= segmentation_[cam].regions_truncated();
    std::memset(explained_[cam], 0,
                static_cast<size_t>(segmentation_[cam].width()) * segmentation_[cam].height());
    images_.rgb[cam] = segmentation_[cam].rgb();
    images_.classes[cam] = segmentation_[cam].classes();
  }
  ResetBlobs();
  for (int cam = 0; cam < 2; ++cam) {
    for (const ColourRegion& region : segmentation_[cam].regions()) {
      const GrayView mask{region_mask_, region.width(), region.height(), region.width()};
      RegionMask(region, segmentation_[cam].runs(), mask);
      if (!AddBlob(cam, region, 0, region_mask_, region.width())) st.blobs_full = true;
    }
  }
  st.time.segment_ms = MsSince(t0);

  n_occluders_ = 0;
  for (int round = 0; round < config_.rounds; ++round) {
    if (round > 0 && DeriveBlobs(0, round, st) + DeriveBlobs(1, round, st) == 0) break;
    // Stereo seeds: pairs with a blob of this round on either side, cheapest first.
    bool pairs_truncated = false;
    SH_RETURN_IF_ERROR(
        PairRegions(calib_, blobs_[0], blobs_[1], config_.pairs, pairs_, &pairs_truncated));
    st.pairs_truncated |= pairs_truncated;
    for (const RegionPair& pair : pairs_) {
      if (blob_round_[0][pair.left] != round && blob_round_[1][pair.right] != round) continue;
      if (ExplainedShare(0, blobs_[0][pair.left]) >= config_.explained_share ||
          ExplainedShare(1, blobs_[1][pair.right]) >= config_.explained_share) {
        continue;
      }
      ++st.pairs;
      Seed seed;
      seed.blob[0] = pair.left;
      seed.blob[1] = pair.right;
      seed.stereo = true;
      seed.centroid_mm = pair.centroid_mm;
      for (int cam = 0; cam < 2; ++cam) {
        float& depth = blob_depth_[cam][cam == 0 ? pair.left : pair.right];
        if (depth == 0.0f) depth = (Camera(calib_, cam).cam_T_left * pair.centroid_mm).z();
      }
      TrySeed(seed, out, st);
      if (st.objects_full) break;
    }
    // Mono seeds: this round's blobs that stay unexplained, from their own image.
    for (int cam = 0; cam < 2 && !st.objects_full; ++cam) {
      for (size_t b = 0; b < blobs_[cam].size(); ++b) {
        if (blob_round_[cam][b] != round ||
            ExplainedShare(cam, blobs_[cam][b]) >= config_.explained_share) {
          continue;
        }
        ++st.mono_seeds;
        Seed seed;
        seed.blob[cam] = static_cast<int>(b);
        seed.surface_mm = BlobDepth(cam, blobs_[cam][b]);
        if (seed.surface_mm == 0.0f) seed.pair_depth_mm = blob_depth_[cam][b];
        TrySeed(seed, out, st);
        if (st.objects_full) break;
      }
    }
  }
  st.blobs[0] = static_cast<uint32_t>(blobs_[0].size());
  st.blobs[1] = static_cast<uint32_t>(blobs_[1].size());
  st.time.search_ms = static_cast<float>(search_ns_) * 1e-6f;
  st.time.refine_ms = static_cast<float>(refine_ns_) * 1e-6f;
  st.time.verify_ms = static_cast<float>(verify_ns_) * 1e-6f;
  st.time.total_ms = MsSince(t0);
  return Status::Ok();
}

}  // namespace sh
