#include "recog/verify/verify.hpp"

#include <cmath>

namespace sh {
namespace {

constexpr float kPi = 3.14159265358979f;
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
                                     const ConstEdgeMapView& edges, const VerifyConfig& config) {
  SH_RETURN_IF_ERROR(CheckVerifyConfig(config));
  const CameraIntrinsics& cam = camera.intrinsics;
  SH_RETURN_IF_ERROR(CheckEdgeMap(cam, edges));
  const double max_r2 = MaxImageRadius2(cam);
  const int w = cam.width, h = cam.height;

  const OrientationTable& table = Orientations();
  // Perpendicular within max_angle <=> |cos(angle between gradient and edge)| <= sin(max_angle).
  const float max_abs_cos = std::sin(config.max_angle_deg * (kPi / 180.0f));

  ImageScore score;
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    for (int r = 0; r < ve.n_runs; ++r) {
      // Each sample's pixel comes from the previous iteration's look-ahead, which also gives
      // the local edge direction (distortion bends edges) at no extra projection.
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
        if (px < 0 || py < 0 || px >= w || py >= h) continue;
        ++score.samples;
        // A neighbour far outside the field may be folded back by the distortion polynomial.
        if (!next.valid || !(next.radius2 <= 4.0 * max_r2)) continue;
        Eigen::Vector2f dir = next.pixel - p.pixel;
        const float len = dir.norm();
        if (!(len > 1e-6f)) continue;  // edge seen end-on: nothing to compare with
        dir /= len;
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
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          if (edges.edge.row(qy)[qx] == 0) continue;
          const uint8_t o = edges.orientation.row(qy)[qx];
          if (std::fabs(table.cos[o] * dir.x() + table.sin[o] * dir.y()) <= max_abs_cos) {
            ++score.confirmed;
            break;
          }
        }
      }
    }
  }
  return score;
}

Result<VerifyResult> VerifyHypothesis(const StereoCalibration& calib,
                                      const ConstEdgeMapView& left_edges,
                                      const ConstEdgeMapView& right_edges,
                                      const PosedModel& hypothesis, const PosedModel* accepted,
                                      size_t n_accepted, const VerifyConfig& config) {
  SH_RETURN_IF_ERROR(CheckVerifyConfig(config));
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.left, left_edges));
  SH_RETURN_IF_ERROR(CheckEdgeMap(calib.right, right_edges));
  if (hypothesis.model == nullptr) {
    return Status::Error(StatusCode::kInvalidArgument, "verify: hypothesis has no model");
  }
  SH_RETURN_IF_ERROR(CheckModel(*hypothesis.model));

  const ViewCamera views[2] = {LeftView(calib), RightView(calib)};
  const ConstEdgeMapView* maps[2] = {&left_edges, &right_edges};
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
    Result<ImageScore> score = ScoreVisibleEdges(views[c], visible, *maps[c], config);
    if (!score.ok()) return score.status();
    scores[c] = *score;
  }
  result.samples_left = scores[0].samples;
  result.samples_right = scores[1].samples;
  result.confirmed_left = scores[0].confirmed;
  result.confirmed_right = scores[1].confirmed;
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
