#include "recog/shape/region_pairs.hpp"

#include <algorithm>
#include <cmath>

#include "recog/stereo/epipolar.hpp"
#include "recog/stereo/triangulation.hpp"

namespace sh {

Status CheckRegionPairConfig(const RegionPairConfig& c) {
  if (!(c.epipolar_base_px >= 0 && c.epipolar_base_px <= 100) ||
      !(c.epipolar_size_share >= 0 && c.epipolar_size_share <= 2) || !(c.max_area_ratio >= 1) ||
      !(c.min_depth_mm > 0 && c.max_depth_mm > c.min_depth_mm)) {
    return Status::Error(StatusCode::kOutOfRange,
                         "region pairing: tolerances out of range (epipolar 0..100 px + share "
                         "0..2, area ratio >= 1, 0 < min depth < max depth)");
  }
  return Status::Ok();
}

Status PairRegions(const StereoCalibration& calib, const Vector<ColourRegion>& left,
                   const Vector<ColourRegion>& right, const RegionPairConfig& config,
                   Vector<RegionPair>& out, bool* truncated) {
  out.clear();
  *truncated = false;
  SH_RETURN_IF_ERROR(CheckRegionPairConfig(config));
  const Eigen::Matrix3d E = EssentialMatrix(calib);
  for (size_t i = 0; i < left.size(); ++i) {
    const ColourRegion& a = left[i];
    const Eigen::Vector2d xl = UndistortPixel(calib.left, {a.cx, a.cy});
    const Eigen::Vector3d line = E * Eigen::Vector3d(xl.x(), xl.y(), 1.0);
    const double line_norm = std::hypot(line.x(), line.y());
    if (!(line_norm > 0)) continue;
    const float tolerance =
        config.epipolar_base_px + config.epipolar_size_share * std::max(a.width(), a.height());
    for (size_t j = 0; j < right.size(); ++j) {
      const ColourRegion& b = right[j];
      if (b.colour != a.colour) continue;
      const double ratio = static_cast<double>(b.area_px) / a.area_px;
      if (ratio > config.max_area_ratio || ratio * config.max_area_ratio < 1.0) continue;
      const Eigen::Vector2d xr = UndistortPixel(calib.right, {b.cx, b.cy});
      const float epi = static_cast<float>(
          std::fabs(line.x() * xr.x() + line.y() * xr.y() + line.z()) / line_norm * calib.right.fx);
      if (epi > tolerance) continue;
      RayMidpoint mid;
      if (!TriangulatePixels(calib, {a.cx, a.cy}, {b.cx, b.cy}, &mid)) continue;
      if (!(mid.depth_a_mm > 0 && mid.depth_b_mm > 0) || mid.p_mm.z() < config.min_depth_mm ||
          mid.p_mm.z() > config.max_depth_mm) {
        continue;
      }
      RegionPair pair;
      pair.left = static_cast<uint16_t>(i);
      pair.right = static_cast<uint16_t>(j);
      pair.epipolar_px = epi;
      pair.cost = epi / tolerance + static_cast<float>(std::fabs(std::log(ratio)));
      pair.centroid_mm = mid.p_mm.cast<float>();
      if (!out.push_back(pair)) {
        *truncated = true;
        // Keep the cheapest: replace the most expensive if this one is cheaper.
        auto worst = std::max_element(out.begin(), out.end(),
                                      [](const auto& x, const auto& y) { return x.cost < y.cost; });
        if (worst->cost > pair.cost) *worst = pair;
      }
    }
  }
  std::sort(out.begin(), out.end(),
            [](const RegionPair& x, const RegionPair& y) { return x.cost < y.cost; });
  return Status::Ok();
}

}  // namespace sh
