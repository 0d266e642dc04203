#include "recog/stereo/sloppy_stereo.hpp"

#include <algorithm>
#include <cmath>

#include "recog/camera/calibration_check.hpp"
#include "recog/stereo/epipolar.hpp"

namespace sh {
namespace {

constexpr double kPi = 3.14159265358979323846;

bool IsFinite(float v) { return std::isfinite(v); }

// Interval [lo, hi] of a 3-D line's parameter, in millimetres.
struct Interval {
  double lo;
  double hi;
};

// Sorts by start and merges overlapping intervals in place; returns the new count. n is at most
// kMaxStereoLineSegments, so insertion sort.
size_t MergeIntervals(Interval* v, size_t n) {
  for (size_t i = 1; i < n; ++i) {
    const Interval x = v[i];
    size_t j = i;
    while (j > 0 && v[j - 1].lo > x.lo) {
      v[j] = v[j - 1];
      --j;
    }
    v[j] = x;
  }
  size_t out = 0;
  for (size_t i = 0; i < n; ++i) {
    if (out > 0 && v[i].lo <= v[out - 1].hi) {
      v[out - 1].hi = std::max(v[out - 1].hi, v[i].hi);
    } else {
      v[out++] = v[i];
    }
  }
  return out;
}

}  // namespace

Status SloppyStereo::Configure(const StereoCalibration& calib, const SloppyStereoConfig& config) {
  configured_ = false;
  SH_RETURN_IF_ERROR(ValidateStereoCalibration(calib));
  if (!(config.epipolar_tolerance_px > 0.0f) || !IsFinite(config.epipolar_tolerance_px)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "epipolar_tolerance_px %g must be finite and positive",
                         config.epipolar_tolerance_px);
  }
  if (!(config.max_ray_gap_mm > 0.0f) || !IsFinite(config.max_ray_gap_mm)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "max_ray_gap_mm %g must be finite and positive", config.max_ray_gap_mm);
  }
  if (!(config.min_overlap_mm >= 0.0f) || !IsFinite(config.min_overlap_mm)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "min_overlap_mm %g must be finite and non-negative",
                         config.min_overlap_mm);
  }
  if (!(config.min_plane_angle_deg >= 0.0f && config.min_plane_angle_deg < 90.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "min_plane_angle_deg %g outside [0, 90)",
                         config.min_plane_angle_deg);
  }
  const WorkingVolume& v = config.volume;
  if (!v.min_mm.allFinite() || !v.max_mm.allFinite() || !v.left_T_box.R.allFinite() ||
      !v.left_T_box.t_mm.allFinite() || !(v.min_mm.array() < v.max_mm.array()).all()) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "working volume must be a finite box with min < max on every axis");
  }
  calib_ = calib;
  config_ = config;
  essential_ = EssentialMatrix(calib);
  left_R_right_ = calib.right_R_left.transpose();
  right_centre_mm_ = RightCentreInLeft(calib);
  baseline_dir_ = right_centre_mm_.normalized();
  // Any unit vector normal to the baseline, then the third axis.
  const Eigen::Vector3d helper =
      std::fabs(baseline_dir_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  baseline_u_ = baseline_dir_.cross(helper).normalized();
  baseline_v_ = baseline_dir_.cross(baseline_u_);
  configured_ = true;
  return Status::Ok();
}

double SloppyStereo::PlaneAngle(const Eigen::Vector3d& ray_left) const {
  // Every epipolar plane contains the baseline; its angle around the baseline is the angle of
  // the ray's component normal to the baseline. The same for the left and the right ray of a
  // scene point, since both lie in its epipolar plane on the same side of the baseline.
  return std::atan2(ray_left.dot(baseline_v_), ray_left.dot(baseline_u_));
}

bool SloppyStereo::AcceptPoint(const Eigen::Vector3d& ray_left, const RightCorner& right,
                               PointStereoStats& stats, Eigen::Vector3d* p_mm) const {
  RayMidpoint m;
  if (!TriangulateMidpoint(Eigen::Vector3d::Zero(), ray_left, right_centre_mm_, right.ray_left,
                           &m) ||
      !(m.depth_a_mm > 0.0) || !(m.depth_b_mm > 0.0)) {
    ++stats.rejected_behind;
    return false;
  }
  if (!(m.gap_mm <= config_.max_ray_gap_mm)) {
    ++stats.rejected_gap;
    return false;
  }
  if (!config_.volume.Contains(m.p_mm)) {
    ++stats.rejected_volume;
    return false;
  }
  *p_mm = m.p_mm;
  return true;
}

Status SloppyStereo::MatchPoints(const StereoPoint2D* left, size_t left_count,
                                 const StereoPoint2D* right, size_t right_count,
                                 Vector<ScenePoint>& points, PointStereoStats* stats_out) {
  points.clear();
  PointStereoStats stats;
  if (stats_out != nullptr) *stats_out = stats;
  if (!configured_) {
    return Status::Error(StatusCode::kFailedPrecondition, "stereo matcher not configured");
  }
  if (left_count > kMaxStereoCorners || right_count > kMaxStereoCorners) {
    return Status::Error(StatusCode::kOutOfRange, "%zu left / %zu right corners; at most %zu each",
                         left_count, right_count, kMaxStereoCorners);
  }
  if ((left_count > 0 && left == nullptr) || (right_count > 0 && right == nullptr)) {
    return Status::Error(StatusCode::kInvalidArgument, "null corner array");
  }
  for (size_t i = 0; i < left_count + right_count; ++i) {
    const StereoPoint2D& c = i < left_count ? left[i] : right[i - left_count];
    if (!IsFinite(c.x_px) || !IsFinite(c.y_px) || !IsFinite(c.strength)) {
      return Status::Error(StatusCode::kInvalidArgument, "%s corner %zu is not finite",
                           i < left_count ? "left" : "right", i < left_count ? i : i - left_count);
    }
  }

  // Right corners: undistort once, and order them by epipolar-plane angle.
  double min_sin_baseline = 1.0;
  for (size_t j = 0; j < right_count; ++j) {
    RightCorner& r = right_[j];
    r.xy = UndistortPixel(calib_.right, Eigen::Vector2d(right[j].x_px, right[j].y_px));
    r.ray_left = (left_R_right_ * Eigen::Vector3d(r.xy.x(), r.xy.y(), 1.0)).normalized();
    r.plane_angle = PlaneAngle(r.ray_left);
    min_sin_baseline = std::min(min_sin_baseline, r.ray_left.cross(baseline_dir_).norm());
    order_[j] = static_cast<uint16_t>(j);
  }
  std::sort(order_, order_ + right_count, [this](uint16_t a, uint16_t b) {
    return right_[a].plane_angle < right_[b].plane_angle;
  });
  for (size_t k = 0; k < right_count; ++k) sorted_angle_[k] = right_[order_[k]].plane_angle;

  // Within T_s of the epipolar line means sin(angle to the epipolar plane) <= tol_norm, and that
  // angle is asin(sin(b) sin(plane angle difference)); see the header.
  const double tol_norm = config_.epipolar_tolerance_px / calib_.right.fx;
  const double ratio = min_sin_baseline > 0.0 ? tol_norm / min_sin_baseline * (1.0 + 1e-9) : 2.0;
  const bool full_scan = ratio >= 1.0;
  const double window = full_scan ? kPi : std::asin(ratio) + 1e-12;

  for (size_t i = 0; i < left_count; ++i) {
    const Eigen::Vector2d xy_left =
        UndistortPixel(calib_.left, Eigen::Vector2d(left[i].x_px, left[i].y_px));
    const Eigen::Vector3d line = RightEpipolarLine(essential_, xy_left);
    if (line.isZero()) continue;  // at the epipole: no epipolar line
    const Eigen::Vector3d ray_left = Eigen::Vector3d(xy_left.x(), xy_left.y(), 1.0).normalized();
    const double angle = PlaneAngle(ray_left);

    // Up to two index ranges of sorted_angle_ (the window may wrap around +-pi).
    size_t begin[2] = {0, 0}, end[2] = {0, 0};
    int ranges = 1;
    if (full_scan) {
      end[0] = right_count;
    } else {
      const double lo = angle - window, hi = angle + window;
      auto lower = [&](double a) {
        return static_cast<size_t>(std::lower_bound(sorted_angle_, sorted_angle_ + right_count, a) -
                                   sorted_angle_);
      };
      auto upper = [&](double a) {
        return static_cast<size_t>(std::upper_bound(sorted_angle_, sorted_angle_ + right_count, a) -
                                   sorted_angle_);
      };
      begin[0] = lower(std::max(lo, -kPi));
      end[0] = upper(std::min(hi, kPi));
      if (lo < -kPi) {
        begin[1] = lower(lo + 2.0 * kPi);
        end[1] = right_count;
        ranges = 2;
      } else if (hi > kPi) {
        begin[1] = 0;
        end[1] = upper(hi - 2.0 * kPi);
        ranges = 2;
      }
    }
    for (int range = 0; range < ranges; ++range) {
      for (size_t k = begin[range]; k < end[range]; ++k) {
        const size_t j = order_[k];
        const RightCorner& r = right_[j];
        const double distance_norm =
            std::fabs(line.x() * r.xy.x() + line.y() * r.xy.y() + line.z());
        if (!(distance_norm <= tol_norm)) continue;
        ++stats.within_tolerance;
        Eigen::Vector3d p_mm;
        if (!AcceptPoint(ray_left, r, stats, &p_mm)) continue;
        ScenePoint sp;
        sp.p_mm = p_mm.cast<float>();
        sp.source.left = static_cast<uint16_t>(i);
        sp.source.right = static_cast<uint16_t>(j);
        sp.quality = std::min(left[i].strength, right[j].strength);
        if (!points.push_back(sp)) {
          stats.truncated = true;
          if (stats_out != nullptr) *stats_out = stats;
          return Status::Error(StatusCode::kResourceExhausted,
                               "scene point capacity %zu reached at left corner %zu of %zu; "
                               "remaining matches dropped",
                               points.capacity(), i, left_count);
        }
        ++stats.accepted;
      }
    }
  }
  if (stats_out != nullptr) *stats_out = stats;
  return Status::Ok();
}

Status SloppyStereo::PrepareLines(const StereoLine2D* lines, size_t count, bool is_left,
                                  PreparedLine* prepared, size_t* unusable) {
  const CameraIntrinsics& cam = is_left ? calib_.left : calib_.right;
  const Eigen::Matrix3d left_R_cam = is_left ? Eigen::Matrix3d::Identity() : left_R_right_;
  const Eigen::Vector3d centre = is_left ? Eigen::Vector3d::Zero() : right_centre_mm_;
  const char* side = is_left ? "left" : "right";
  for (size_t i = 0; i < count; ++i) {
    const StereoLine2D& line = lines[i];
    PreparedLine& out = prepared[i];
    out.usable = false;
    if (!line.point_px.allFinite() || !line.direction.allFinite() ||
        std::fabs(line.direction.norm() - 1.0f) > 1e-3f) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "%s line %zu: point and unit direction must be finite", side, i);
    }
    if (line.segment_count > kMaxStereoLineSegments) {
      return Status::Error(StatusCode::kInvalidArgument, "%s line %zu: %u segments, at most %zu",
                           side, i, line.segment_count, kMaxStereoLineSegments);
    }
    const Eigen::Vector2d p0 = line.point_px.cast<double>();
    const Eigen::Vector2d dir = line.direction.cast<double>().normalized();
    double t_min = 1e300, t_max = -1e300;
    for (uint8_t k = 0; k < line.segment_count; ++k) {
      const StereoSegment2D& s = line.segments[k];
      if (!IsFinite(s.x0_px) || !IsFinite(s.y0_px) || !IsFinite(s.x1_px) || !IsFinite(s.y1_px)) {
        return Status::Error(StatusCode::kInvalidArgument, "%s line %zu: segment %u not finite",
                             side, i, k);
      }
      const Eigen::Vector2d ends[2] = {{s.x0_px, s.y0_px}, {s.x1_px, s.y1_px}};
      for (int e = 0; e < 2; ++e) {
        const double t = (ends[e] - p0).dot(dir);
        t_min = std::min(t_min, t);
        t_max = std::max(t_max, t);
        out.ray_left[2 * k + e] = (left_R_cam * PixelRay(cam, ends[e])).cast<float>();
      }
    }
    out.segment_count = line.segment_count;
    if (line.segment_count == 0 || !(t_max - t_min > 1e-3)) {
      ++*unusable;
      continue;
    }
    // The plane through the ends and the middle of the supported extent (see header).
    const Eigen::Vector2d samples[3] = {p0 + t_min * dir, p0 + 0.5 * (t_min + t_max) * dir,
                                        p0 + t_max * dir};
    Eigen::Vector3d normal_cam;
    if (!FitLinePlaneNormal(cam, samples, 3, &normal_cam)) {
      ++*unusable;
      continue;
    }
    out.plane.normal = left_R_cam * normal_cam;
    out.plane.d_mm = out.plane.normal.dot(centre);
    out.usable = true;
  }
  return Status::Ok();
}

Status SloppyStereo::MatchLines(const StereoLine2D* left, size_t left_count,
                                const StereoLine2D* right, size_t right_count,
                                Vector<SceneLine>& lines, LineStereoStats* stats_out) {
  lines.clear();
  LineStereoStats stats;
  if (stats_out != nullptr) *stats_out = stats;
  if (!configured_) {
    return Status::Error(StatusCode::kFailedPrecondition, "stereo matcher not configured");
  }
  if (left_count > kMaxStereoLines || right_count > kMaxStereoLines) {
    return Status::Error(StatusCode::kOutOfRange, "%zu left / %zu right lines; at most %zu each",
                         left_count, right_count, kMaxStereoLines);
  }
  if ((left_count > 0 && left == nullptr) || (right_count > 0 && right == nullptr)) {
    return Status::Error(StatusCode::kInvalidArgument, "null line array");
  }
  SH_RETURN_IF_ERROR(PrepareLines(left, left_count, true, left_lines_, &stats.unusable_lines));
  SH_RETURN_IF_ERROR(PrepareLines(right, right_count, false, right_lines_, &stats.unusable_lines));

  const double min_sin_angle = std::sin(config_.min_plane_angle_deg * kPi / 180.0);
  const Eigen::Vector3d origins[2] = {Eigen::Vector3d::Zero(), right_centre_mm_};
  for (size_t i = 0; i < left_count; ++i) {
    const PreparedLine& l = left_lines_[i];
    if (!l.usable) continue;
    for (size_t j = 0; j < right_count; ++j) {
      const PreparedLine& r = right_lines_[j];
      if (!r.usable) continue;
      ++stats.pairs;
      Line3 line;
      if (!IntersectPlanes(l.plane, r.plane, min_sin_angle, &line)) {
        ++stats.rejected_degenerate;
        continue;
      }
      double v0 = 0.0, v1 = 0.0;
      if (!config_.volume.Clip(line, &v0, &v1)) {
        ++stats.rejected_volume;
        continue;
      }
      // Each image's support on the 3-D line, clipped to the volume and merged.
      Interval support[2][kMaxStereoLineSegments];
      size_t support_count[2] = {0, 0};
      const PreparedLine* sides[2] = {&l, &r};
      for (int side = 0; side < 2; ++side) {
        const PreparedLine& p = *sides[side];
        for (uint8_t k = 0; k < p.segment_count; ++k) {
          double s0 = 0.0, s1 = 0.0;
          if (!RayLineParameter(line, origins[side],
                                p.ray_left[size_t{2} * k].cast<double>().normalized(), &s0) ||
              !RayLineParameter(line, origins[side],
                                p.ray_left[size_t{2} * k + 1].cast<double>().normalized(), &s1)) {
            continue;
          }
          const double lo = std::max(std::min(s0, s1), v0);
          const double hi = std::min(std::max(s0, s1), v1);
          if (lo < hi) support[side][support_count[side]++] = {lo, hi};
        }
        support_count[side] = MergeIntervals(support[side], support_count[side]);
      }
      // Overlap of the two merged supports.
      double overlap = 0.0, first = 1e300, last = -1e300;
      size_t a = 0, b = 0;
      while (a < support_count[0] && b < support_count[1]) {
        const Interval& x = support[0][a];
        const Interval& y = support[1][b];
        const double lo = std::max(x.lo, y.lo), hi = std::min(x.hi, y.hi);
        if (lo < hi) {
          overlap += hi - lo;
          first = std::min(first, lo);
          last = std::max(last, hi);
        }
        if (x.hi < y.hi) {
          ++a;
        } else {
          ++b;
        }
      }
      if (!(overlap >= config_.min_overlap_mm) || !(overlap > 0.0)) {
        ++stats.rejected_overlap;
        continue;
      }
      SceneLine sl;
      sl.a_mm = line.At(first).cast<float>();
      sl.b_mm = line.At(last).cast<float>();
      sl.source.left = static_cast<uint16_t>(i);
      sl.source.right = static_cast<uint16_t>(j);
      sl.quality = static_cast<float>(overlap);
      if (!lines.push_back(sl)) {
        stats.truncated = true;
        if (stats_out != nullptr) *stats_out = stats;
        return Status::Error(StatusCode::kResourceExhausted,
                             "scene line capacity %zu reached at left line %zu of %zu; remaining "
                             "matches dropped",
                             lines.capacity(), i, left_count);
      }
      ++stats.accepted;
    }
  }
  if (stats_out != nullptr) *stats_out = stats;
  return Status::Ok();
}

}  // namespace sh
