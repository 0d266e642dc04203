// The shape path's search over the view database (seed 001 sections IV-C, IV-D): a
// silhouette window projected into the database's PCA space, and the nearest stored views. The
// database itself (format and validating reader) is tables/shape_views_view.hpp.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "recog/base/vector.hpp"
#include "recog/shape/shape_window.hpp"
#include "tables/shape_views_view.hpp"

namespace sh {

struct ViewMatch {
  uint32_t view = 0;
  float distance2 = 0;  // squared distance in PCA space
};

// Projection of a window into PCA space, as raw Q3.13 coefficients (component_stride entries,
// padding zero).
struct ShapeCoefficients {
  QCoefficient::Raw c[kMaxShapeComponents] = {};
};

// c_k = basis_k . (window - mean) for k < n_components (basis rows of kWindowPixels Q2.14 raw
// entries), stored as raw Q3.13 (saturating); entries n_components .. stride - 1 are zero. The
// builder and ProjectWindow both use it.
void ProjectShapeWindow(const float* mean, const QBasis::Raw* basis, int n_components, int stride,
                        const ShapeWindow& window, ShapeCoefficients* out);

// Components summed together by the projection; a share of the projection is whole blocks.
inline constexpr int kProjectBlock = 8;

// PCA coefficients of a window in the database's space.
void ProjectWindow(const ShapeViewsView& views, const ShapeWindow& window, ShapeCoefficients* out);
// Share `share` of `shares` of ProjectWindow's coefficients (contiguous blocks of kProjectBlock
// components; the last share writes the padding): the same values bit for bit, so that
// `shares` threads together write what ProjectWindow writes.
void ProjectWindowShare(const ShapeViewsView& views, const ShapeWindow& window, int share,
                        int shares, ShapeCoefficients* out);

// The `k` nearest views among the models whose bit is set in `model_mask`, nearest first
// (exhaustive, with partial-distance early exit: views go in groups of four, and a group is
// abandoned once every running sum in it reaches the k-th best so far; the components come in
// decreasing variance, so most views are abandoned after a few blocks). Of equal distances
// the earlier view comes first.
void NearestViews(const ShapeViewsView& views, const ShapeCoefficients& query, uint32_t model_mask,
                  size_t k, Vector<ViewMatch>& out);

// The ray frame of a point: z along the viewing ray from the camera centre through x_cam_mm,
// turned from the camera frame by the smallest rotation (so on the optical axis it is the
// camera frame, and the image axes keep their directions nearby). Returns cam_R_ray.
Eigen::Matrix3f RayFrame(const Eigen::Vector3f& x_cam_mm);

}  // namespace sh
