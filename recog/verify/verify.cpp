#include "recog/verify/verify.hpp"

#include <cmath>

namespace sh {
namespace {

constexpr float kPi = 3.14159265358979f;

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
  const int max_offset = static_cast<int>(config.max_distance_px);
  const int w = cam.width, h = cam.height;

  const OrientationTable& table = Orientations();
  // Perpendicular within max_angle <=> |cos(angle between gradient and edge)| <= sin(max_angle).
  const float max_abs_cos = std::sin(config.max_angle_deg * (kPi / 180.0f));

  ImageScore score;
  for (int k = 0; k < visible.n_edges; ++k) {
    const VisibleEdge& ve = visible.edges[k];
    const float ahead = 0.25f / ve.n_samples;  // a quarter sample: the local edge direction
    for (int r = 0; r < ve.n_runs; ++r) {
      for (int i = ve.runs[r].first; i < ve.runs[r].end; ++i) {
        const float s = SampleImageFraction(i, ve.n_samples);
        Eigen::Vector2f p, q;
        if (!ProjectInView(cam, max_r2, PointAtImageFraction(ve, s), &p)) continue;
        const int px = static_cast<int>(std::floor(p.x() + 0.5f));
        const int py = static_cast<int>(std::floor(p.y() + 0.5f));
        if (px < 0 || py < 0 || px >= w || py >= h) continue;
        ++score.samples;
        // Local direction from a point a quarter sample further on (distortion bends edges).
        if (!ProjectInView(cam, 4.0 * max_r2, PointAtImageFraction(ve, s + ahead), &q)) continue;
        Eigen::Vector2f dir = q - p;
        const float len = dir.norm();
        if (!(len > 1e-6f)) continue;  // edge seen end-on: nothing to compare with
        dir /= len;
        const Eigen::Vector2f normal(-dir.y(), dir.x());
        // Nearest offsets first: 0, +1, -1, +2, -2, ...
        for (int step = 0; step <= 2 * max_offset; ++step) {
          const int offset = (step + 1) / 2 * ((step & 1) ? 1 : -1);
          const int qx = static_cast<int>(std::floor(p.x() + offset * normal.x() + 0.5f));
          const int qy = static_cast<int>(std::floor(p.y() + offset * normal.y() + 0.5f));
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
