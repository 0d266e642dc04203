#include "recog/verify/verify.hpp"

#include <cmath>

#include "recog/base/angles.hpp"

namespace sh {
namespace {

// Axis search reach for max_distance_px = 32 at 45 degrees, the largest the config allows.
constexpr int kMaxSearchOffset = 46;

// Unit gradient direction of each edge-map orientation code (256 steps per 180 degrees,
// recog/image/edge_map.hpp), so the per-pixel test is a dot product instead of an atan2.
struct OrientationTable {
  float cos[256];
  float sin[256];
};

const OrientationTable& Orientations() {
  static const OrientationTable table = [] {
    OrientationTable t{};
    for (int o = 0; o < 256; ++o) {
      const double angle = o * 3.14159265358979323846 / 256.0;
      t.cos[o] = static_cast<float>(std::cos(angle));
      t.sin[o] = static_cast<float>(std::sin(angle));
    }
    return t;
  }();
  return table;
}

// A point's distorted pixel and its squared normalised radius (x/z)^2 + (y/z)^2.
struct Projected {
  bool valid = false;  // in front of the camera
  double radius2 = 0;
  Eigen::Vector2f pixel{0, 0};
};

Projected Project(const CameraIntrinsics& cam, const Eigen::Vector3f& x_cam) {
  Projected out;
  if (!(x_cam.z() > 0.0f)) return out;
  const double x = double{x_cam.x()} / x_cam.z(), y = double{x_cam.y()} / x_cam.z();
  const Eigen::Vector2d d = Distort(cam, {x, y});
  out.valid = true;
  out.radius2 = x * x + y * y;
  out.pixel = {static_cast<float>(cam.fx * d.x() + cam.cx),
               static_cast<float>(cam.fy * d.y() + cam.cy)};
  return out;
}

// Calls visit(px, py, pixel, dir) for each sample of `ve` that projects inside the image, in
// order along the edge, until it returns false: its nearest pixel, its sub-pixel position and
// the unit direction of the projected edge there (distortion bends edges), or a zero direction
// where it cannot be told (the edge seen end-on, or its neighbour folded back by the distortion
// polynomial from far outside the field).
template <typename Visit>
void ForEachInImageSample(const CameraIntrinsics& cam, double max_r2, const VisibleEdge& ve,
                          Visit&& visit) {
  for (int r = 0; r < ve.n_runs; ++r) {
    // Each sample's pixel comes from the previous iteration's look-ahead, which also gives the
    // local edge direction at no extra projection.
    const int first = ve.runs[r].first;
    Projected here =
        Project(cam, PointAtImageFraction(ve, SampleImageFraction(first, ve.n_samples)));
    for (int i = first; i < ve.runs[r].end; ++i) {
      // The next sample, or the edge's end half a step beyond the last one.
      const float s_next = std::min(1.0f, SampleImageFraction(i + 1, ve.n_samples));
      const Projected next = Project(cam, PointAtImageFraction(ve, s_next));
      const Projected p = here;
      here = next;
      if (!p.valid || !(p.radius2 <= max_r2)) continue;  // outside the image's field
      const int px = static_cast<int>(std::floor(p.pixel.x() + 0.5f));
      const int py = static_cast<int>(std::floor(p.pixel.y() + 0.5f));
      if (px < 0 || py < 0 || px >= cam.width || py >= cam.height) continue;
      Eigen::Vector2f dir = Eigen::Vector2f::Zero();
      if (next.valid && next.radius2 <= 4.0 * max_r2) {
        const Eigen::Vector2f d = next.pixel - p.pixel;
        const float len = d.norm();
        if (len > 1e-6f) dir = d / len;
      }
      if (!visit(px, py, p.pixel, dir)) return;
    }
  }
}

// Sums of the grey-level steps across an edge, over some of its samples.
struct StepSums {
  double centre = 0;           // step across the edge
  double plus = 0, minus = 0;  // steps of the same sense beyond either side
  int n = 0;
  void Add(float c, float p, float m) {
    centre += c;
    plus += p;
    minus += m;
    ++n;
  }
};

// The faint-edge test of VerifyConfig::faint_edges for one edge with `samples` in-image
// samples.
bool FaintEdgeConfirmed(const CameraIntrinsics& cam, double max_r2, const VisibleEdge& ve,
                        int samples, const GreyEvidence& grey, const VerifyConfig& config) {
  const ConstGrayView& img = grey.image;
  const float d = config.faint_offset_px;
  const double min_step =
      std::max<double>(config.faint_min_step, config.faint_min_step_sigmas * grey.noise_sigma);
  StepSums all, quarters[4];
  int index = 0;    // in-image samples visited, for the quarter
  int current = 0;  // the quarter being summed
  bool failed = false;
  ForEachInImageSample(
      cam, max_r2, ve, [&](int, int, const Eigen::Vector2f& pixel, const Eigen::Vector2f& dir) {
        const int quarter = std::min(3, 4 * index++ / samples);
        if (quarter != current) {
          // Each quarter must step by half the minimum (below), whatever the sense: most edges of
          // wrong hypotheses fail the first quarter, at a quarter of the work.
          const StepSums& done = quarters[current];
          if (done.n > 0 && std::fabs(done.centre / done.n) < 0.5 * min_step) {
            failed = true;
            return false;
          }
          current = quarter;
        }
        if (dir.isZero()) return true;
        const Eigen::Vector2f n(-dir.y(), dir.x());
        const Eigen::Vector2f far_plus = pixel + 3.0f * d * n, far_minus = pixel - 3.0f * d * n;
        const auto inside = [&](const Eigen::Vector2f& q) {
          return q.x() >= 0.0f && q.y() >= 0.0f && q.x() < float(img.width - 1) &&
                 q.y() < float(img.height - 1);
        };
        if (!inside(far_plus) || !inside(far_minus)) return true;
        const Eigen::Vector2f plus = pixel + d * n, minus = pixel - d * n;
        const float g_plus = SampleGrayInside(img, plus.x(), plus.y());
        const float g_minus = SampleGrayInside(img, minus.x(), minus.y());
        const float centre = g_plus - g_minus;
        // Beyond each side, the step of the same sense: a ramp (a soft shadow, shading) or a
        // stronger edge a few pixels off steps there as much as across the model's edge.
        const float outer_plus = SampleGrayInside(img, far_plus.x(), far_plus.y()) - g_plus;
        const float outer_minus = g_minus - SampleGrayInside(img, far_minus.x(), far_minus.y());
        all.Add(centre, outer_plus, outer_minus);
        quarters[quarter].Add(centre, outer_plus, outer_minus);
        return true;
      });
  if (failed || all.n < config.faint_min_samples) return false;
  const double mean = all.centre / all.n;
  const double sense = mean >= 0.0 ? 1.0 : -1.0;
  const double size = sense * mean;
  if (size < min_step) return false;
  // The noise of one sample's step is about that of two pixels' difference, sqrt(2) sigma
  // (bilinear weights make it smaller, neighbouring samples sharing pixels make the mean's
  // larger), and the mean's 1 / sqrt(n) of it. With the defaults this bound is the larger of the
  // two under 57 samples.
  if (size < config.faint_snr * std::sqrt(2.0 / all.n) * grey.noise_sigma) return false;
  // The step stands alone: at most half of it continues beyond either side.
  if (sense * all.plus / all.n > 0.5 * size || sense * all.minus / all.n > 0.5 * size) {
    return false;
  }
  for (const StepSums& q : quarters) {
    if (q.n == 0) continue;  // a quarter hidden or outside the image
    if (!(sense * q.centre / q.n >= 0.5 * min_step)) return false;
  }
  return true;
}

}  // namespace

const char* VerifyReasonName(VerifyReason reason) {
  switch (reason) {
    case VerifyReason::kAccepted:
      return "accepted";
    case VerifyReason::kBehindCamera:
      return "model behind a camera";
    case VerifyReason::kTooFewSamplesLeft:
      return "too few visible samples in the left image";
    case VerifyReason::kTooFewSamplesRight:
      return "too few visible samples in the right image";
    case VerifyReason::kLowScoreLeft:
      return "too few confirmed samples in the left image";
    case VerifyReason::kLowScoreRight:
      return "too few confirmed samples in the right image";
  }
  return "unknown";
}

Status CheckVerifyConfig(const VerifyConfig& c) {
  if (!(c.max_distance_px >= 0.0f && c.max_distance_px <= 32.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: max_distance_px %g outside [0, 32]",
                         c.max_distance_px);
  }
  if (!(c.max_angle_deg >= 0.0f && c.max_angle_deg <= 90.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: max_angle_deg %g outside [0, 90]",
                         c.max_angle_deg);
  }
  if (!(c.min_fraction >= 0.0f && c.min_fraction <= 1.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: min_fraction %g outside [0, 1]",
                         c.min_fraction);
  }
  if (c.min_samples < 1) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: min_samples %d must be >= 1",
                         c.min_samples);
  }
  if (!(c.sample_step_px >= 0.05f && c.sample_step_px <= 64.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "verify: sample_step_px %g outside [0.05, 64]", c.sample_step_px);
  }
  if (!(c.faint_offset_px >= 0.5f && c.faint_offset_px <= 8.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "verify: faint_offset_px %g outside [0.5, 8]", c.faint_offset_px);
  }
  if (!(c.faint_min_step_sigmas >= 0.0f && c.faint_min_step_sigmas <= 100.0f) ||
      !(c.faint_min_step > 0.0f && c.faint_min_step <= 255.0f) ||
      !(c.faint_snr >= 0.0f && c.faint_snr <= 1000.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "verify: faint-edge step %g sigmas / %g grey levels / snr %g outside "
                         "[0, 100] / (0, 255] / [0, 1000]",
                         c.faint_min_step_sigmas, c.faint_min_step, c.faint_snr);
  }
  if (c.faint_min_samples < 4) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: faint_min_samples %d must be >= 4",
                         c.faint_min_samples);
  }
  if (!(c.min_depth_mm > 0.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: min_depth_mm %g must be > 0",
                         c.min_depth_mm);
  }
  return Status::Ok();
}

Status CheckEdgeMap(const CameraIntrinsics& cam, const ConstEdgeMapView& edges) {
  if (edges.edge.empty() || edges.orientation.empty()) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: edge map is empty or null");
  }
  if (edges.edge.width != cam.width || edges.edge.height != cam.height ||
      edges.orientation.width != cam.width || edges.orientation.height != cam.height) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "verify: edge map %dx%d (orientation %dx%d) does not match camera %dx%d",
                         edges.edge.width, edges.edge.height, edges.orientation.width,
                         edges.orientation.height, cam.width, cam.height);
  }
  if (edges.edge.stride < edges.edge.width || edges.orientation.stride < edges.orientation.width) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: edge map stride below width");
  }
  return Status::Ok();
}

Result<ImageScore> ScoreVisibleEdges(const ViewCamera& camera, const VisibleEdgeSet& visible,
                                     const ConstEdgeMapView& edges, const VerifyConfig& config,
                                     const GreyEvidence& grey) {
  SH_RETURN_IF_ERROR(CheckVerifyConfig(config));
  const CameraIntrinsics& cam = camera.intrinsics;
  SH_RETURN_IF_ERROR(CheckEdgeMap(cam, edges));
  const bool faint = config.faint_edges && !grey.image.empty();
  if (faint && (grey.image.width != cam.width || grey.image.height != cam.height)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "verify: grey image %dx%d does not match camera %dx%d", grey.image.width,
                         grey.image.height, cam.width, cam.height);
  }
  const double max_r2 = MaxImageRadius2(cam);

  const OrientationTable& table = Orientations();
  // Perpendicular within max_angle <=> |cos(angle between gradient and edge)| <= sin(max_angle).
  const float max_abs_cos = std::sin(config.max_angle_deg * (kPi / 180.0f));

  ImageScore score;
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    int samples = 0, confirmed = 0;
    ForEachInImageSample(
        cam, max_r2, ve, [&](int px, int py, const Eigen::Vector2f&, const Eigen::Vector2f& dir) {
          ++samples;
          if (dir.isZero()) return true;
          // Search along the image axis closest to the edge's normal: a thin 8-connected edge
          // line has a pixel in every column (or row) it crosses, which a walk along an oblique
          // normal could step over. An axis offset k is k * |normal component| away from the
          // edge's line, so the reach is scaled to keep max_distance_px perpendicular.
          const bool vertical = std::fabs(dir.x()) >= std::fabs(dir.y());
          const float across = vertical ? std::fabs(dir.x()) : std::fabs(dir.y());  // |normal|
          const int reach =
              std::min(kMaxSearchOffset, static_cast<int>(config.max_distance_px / across + 1e-4f));
          const int ax = vertical ? 0 : 1, ay = vertical ? 1 : 0;
          // Nearest offsets first: 0, +1, -1, +2, -2, ...
          for (int step = 0; step <= 2 * reach; ++step) {
            const int offset = (step + 1) / 2 * ((step & 1) ? 1 : -1);
            const int qx = px + offset * ax;
            const int qy = py + offset * ay;
            if (qx < 0 || qy < 0 || qx >= cam.width || qy >= cam.height) continue;
            if (edges.edge.row(qy)[qx] == 0) continue;
            const uint8_t o = edges.orientation.row(qy)[qx];
            if (std::fabs(table.cos[o] * dir.x() + table.sin[o] * dir.y()) <= max_abs_cos) {
              ++confirmed;
              break;
            }
          }
          return true;
        });
    if (faint && 2 * confirmed <= samples && samples >= config.faint_min_samples &&
        FaintEdgeConfirmed(cam, max_r2, ve, samples, grey, config)) {
      confirmed = samples;
      ++score.faint_edges;
    }
    score.samples += samples;
    score.confirmed += confirmed;
  }
  return score;
}

Result<VerifyResult> VerifyHypothesis(const StereoCalibration& calib,
                                      const ConstEdgeMapView& left_edges,
                                      const ConstEdgeMapView& right_edges,
                                      const PosedModel& hypothesis, const PosedModel* accepted,
                                      size_t n_accepted, const VerifyConfig& config,
                                      const GreyEvidence& left_grey,
                                      const GreyEvidence& right_grey) {
  SH_RETURN_IF_ERROR(CheckVerifyConfig(config));
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.left, left_edges));
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.right, right_edges));
  if (hypothesis.model == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: hypothesis has no model");
  }
  SH_RETURN_IF_ERROR(CheckModel(*hypothesis.model));

  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  const ConstEdgeMapView* maps[2] = {&left_edges, &right_edges};
  const GreyEvidence* greys[2] = {&left_grey, &right_grey};
  VerifyResult result;
  for (const ViewCamera& view : views) {
    if (!(MinCornerDepthMm(view, hypothesis) >= config.min_depth_mm)) {
      result.reason = VerifyReason::kBehindCamera;
      return result;
    }
  }
  ImageScore scores[2];
  for (int c = 0; c < 2; ++c) {
    VisibleEdgeSet visible;
    SH_RETURN_IF_ERROR(ComputeVisibleEdges(views[c], hypothesis, accepted, n_accepted,
                                           config.sample_step_px, config.min_depth_mm, &visible));
    Result<ImageScore> score = ScoreVisibleEdges(views[c], visible, *maps[c], config, *greys[c]);
    if (!score.ok()) return score.status();
    scores[c] = *score;
  }
  result.samples_left = scores[0].samples;
  result.samples_right = scores[1].samples;
  result.confirmed_left = scores[0].confirmed;
  result.confirmed_right = scores[1].confirmed;
  result.faint_edges_left = scores[0].faint_edges;
  result.faint_edges_right = scores[1].faint_edges;
  result.score_left = scores[0].samples > 0 ? float(scores[0].confirmed) / scores[0].samples : 0.0f;
  result.score_right =
      scores[1].samples > 0 ? float(scores[1].confirmed) / scores[1].samples : 0.0f;
  if (result.samples_left < config.min_samples) {
    result.reason = VerifyReason::kTooFewSamplesLeft;
  } else if (result.samples_right < config.min_samples) {
    result.reason = VerifyReason::kTooFewSamplesRight;
  } else if (result.score_left < config.min_fraction) {
    result.reason = VerifyReason::kLowScoreLeft;
  } else if (result.score_right < config.min_fraction) {
    result.reason = VerifyReason::kLowScoreRight;
  } else {
    result.accepted = true;
    result.reason = VerifyReason::kAccepted;
  }
  return result;
}

}  // namespace sh
