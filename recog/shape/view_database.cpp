#include "recog/shape/view_database.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstddef>
#include <limits>

namespace sh {
namespace {

// A k-best list kept sorted by distance (small k: insertion).
void Insert(Vector<ViewMatch>& best, size_t k, ViewMatch m) {
  if (best.size() == k && m.distance2 >= best.back().distance2) return;
  if (best.size() < k) {
    (void)best.push_back(m);
  } else {
    best.back() = m;
  }
  for (size_t i = best.size() - 1; i > 0 && best[i].distance2 < best[i - 1].distance2; --i) {
    std::swap(best[i], best[i - 1]);
  }
}

// Components of the blocks [first_block, end_block) of eight (the last block may be shorter).
void ProjectBlocks(const float* mean, const QBasis::Raw* basis, int n_components,
                   const ShapeWindow& window, int first_block, int end_block,
                   ShapeCoefficients* out) {
  float centred[kWindowPixels];
  for (int i = 0; i < kWindowPixels; ++i) centred[i] = window.v[i] - mean[i];
  // Each component's sum runs over the pixels in order, as one loop per component would; a few
  // components at once make independent sums the processor overlaps (and the compiler puts in
  // the lanes of one vector), the same values bit for bit.
  for (int k0 = first_block * kProjectBlock; k0 < std::min(n_components, end_block * kProjectBlock);
       k0 += kProjectBlock) {
    const int n = std::min(kProjectBlock, n_components - k0);
    const QBasis::Raw* b[kProjectBlock];
    for (int j = 0; j < kProjectBlock; ++j) {
      b[j] = basis + static_cast<size_t>(k0 + std::min(j, n - 1)) * kWindowPixels;
    }
    float sum[kProjectBlock] = {};
    for (int i = 0; i < kWindowPixels; ++i) {
      for (int j = 0; j < kProjectBlock; ++j) sum[j] += centred[i] * static_cast<float>(b[j][i]);
    }
    // Basis raw units -> value: divide by 2^14; value -> coefficient raw (saturating).
    for (int j = 0; j < n; ++j) {
      out->c[k0 + j] = QCoefficient::FromDouble(double(sum[j]) / QBasis::kScale).raw();
    }
  }
}

}  // namespace

void ProjectShapeWindow(const float* mean, const QBasis::Raw* basis, int n_components, int stride,
                        const ShapeWindow& window, ShapeCoefficients* out) {
  const int blocks = (n_components + kProjectBlock - 1) / kProjectBlock;
  ProjectBlocks(mean, basis, n_components, window, 0, blocks, out);
  for (int k = n_components; k < stride; ++k) out->c[k] = 0;
}

void ProjectWindow(const ShapeViewsView& views, const ShapeWindow& window, ShapeCoefficients* out) {
  ProjectShapeWindow(views.mean(), views.basis(), views.header().n_components,
                     views.header().component_stride, window, out);
}

void ProjectWindowShare(const ShapeViewsView& views, const ShapeWindow& window, int share,
                        int shares, ShapeCoefficients* out) {
  const int n_components = views.header().n_components;
  const int blocks = (n_components + kProjectBlock - 1) / kProjectBlock;
  ProjectBlocks(views.mean(), views.basis(), n_components, window, blocks * share / shares,
                blocks * (share + 1) / shares, out);
  if (share + 1 == shares) {
    for (int k = n_components; k < views.header().component_stride; ++k) out->c[k] = 0;
  }
}

void NearestViews(const ShapeViewsView& views, const ShapeCoefficients& query, uint32_t model_mask,
                  size_t k, Vector<ViewMatch>& out) {
  out.clear();
  k = std::min(k, out.capacity());
  if (k == 0) return;
  const int stride = views.header().component_stride;
  constexpr int kBlock = 16;  // components summed between early-exit checks
  // Views compared at once: independent sums the processor overlaps (the lanes of one vector),
  // each over the components in order, as one view at a time would sum them.
  constexpr uint32_t kTogether = 4;
  // Squared distances in raw units (2^-26 per unit^2); floats hold them to 24 bits, plenty for
  // ranking.
  float worst = std::numeric_limits<float>::infinity();
  for (uint32_t m = 0; m < views.model_count(); ++m) {
    if (!(model_mask & (1u << m))) continue;
    const ShapeModelRecord& rec = views.shape_model(m);
    const uint32_t end_view = rec.first_view + rec.n_views;
    for (uint32_t v0 = rec.first_view; v0 < end_view; v0 += kTogether) {
      const uint32_t n = std::min(kTogether, end_view - v0);
      const QCoefficient::Raw* c[kTogether];
      for (uint32_t g = 0; g < kTogether; ++g) c[g] = views.coefficients(v0 + std::min(g, n - 1));
      float d2[kTogether] = {};
      // A sum that reaches the worst of a full list at a check cannot enter it: the views stop
      // once all of theirs have (a view that goes on is refused by Insert, as the list's worst
      // only falls).
      int i = 0;
      for (; i < stride; i += kBlock) {
        const int end = std::min(stride, i + kBlock);
        for (int j = i; j < end; ++j) {
          for (uint32_t g = 0; g < kTogether; ++g) {
            const float d = static_cast<float>(int32_t{query.c[j]} - int32_t{c[g][j]});
            d2[g] += d * d;
          }
        }
        bool all_out = true;
        for (uint32_t g = 0; g < n; ++g) all_out &= d2[g] >= worst;
        if (all_out) break;
      }
      if (i < stride) continue;
      for (uint32_t g = 0; g < n; ++g) {
        if (d2[g] >= worst) continue;
        Insert(out, k,
               {v0 + g, d2[g] / static_cast<float>(QCoefficient::kScale * QCoefficient::kScale)});
        if (out.size() == k) {
          worst = out.back().distance2 *
                  static_cast<float>(QCoefficient::kScale * QCoefficient::kScale);
        }
      }
    }
  }
}

Eigen::Matrix3f RayFrame(const Eigen::Vector3f& x_cam_mm) {
  const float n = x_cam_mm.norm();
  if (!(n > 0)) return Eigen::Matrix3f::Identity();
  return Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), x_cam_mm / n)
      .toRotationMatrix();
}

}  // namespace sh
